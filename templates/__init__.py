"""Jinja2 report templates (installed as ``drillfric.templates``)."""
