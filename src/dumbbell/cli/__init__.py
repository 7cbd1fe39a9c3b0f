"""Layer 5, the command line: parse arguments, call analysis, then io / plot / animation to
write the outputs, and map errors to exit codes. ``dumbbell.cli:main`` is the console script."""

from .app import EXIT_USAGE, EXIT_VERDICT, build_parser, main

__all__ = ["EXIT_USAGE", "EXIT_VERDICT", "build_parser", "main"]
