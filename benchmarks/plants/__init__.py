"""Validation plants written from the physics, independent of drillfric's own simulator.

A plant here may import numpy, scipy and numba only — never drillfric's plant, simulator,
kernels, torque-and-drag or well-path modules (the import-linter contract
``benchmarks-plants-independent`` in pyproject.toml and tests/test_lumped_plant.py hold
this). :mod:`benchmarks.plants.lumped` is the lumped multi-body torsional string.
"""
