"""The ``geardyn`` command line (typer): ``geardyn --help``."""
