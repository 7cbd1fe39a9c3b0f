"""Layer 5, the command line: parse arguments, call analysis, then io / plot / animation to
write the outputs, and map errors to exit codes. ``dumbbell.cli:main`` is the console script."""

from .app import main as main  # the console script; the package has no API of its own

#: No public names: the command line is the ``dumbbell`` console script.
__all__: list[str] = []
