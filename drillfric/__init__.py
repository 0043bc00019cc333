"""drillfric — downhole friction factors and bit speed from rig surface data.

Implements the adaptive observer of Aarsnes, Auriol, Di Meglio & Shor, "Estimating
friction factors while drilling", J. Petroleum Science and Engineering 179 (2019) 80–91,
on top of a minimum-curvature well path and a soft-string torque-and-drag model.
See docs/theory.md and ``../shared/design/THEORY.md`` for the equations.
"""

__version__ = "0.1.0"
