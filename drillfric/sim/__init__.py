"""Synthetic wells with known truth (docs/simulator.md): scenarios of stands, the plant
driven stand by stand (:mod:`~drillfric.sim.run`), and how a rig recorder would log it
(:mod:`~drillfric.sim.recorder`)."""
