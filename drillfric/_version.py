"""drillfric's version (one place: the package, summary.json and the wheel read it here)."""

__version__ = "0.1.0"
