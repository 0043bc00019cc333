"""drillfric command-line interface (installed as ``drillfric.cli``).

Thin by design: parse, build the config, call the library, print a summary, choose the exit
code. Library code never prints and never exits.
"""
