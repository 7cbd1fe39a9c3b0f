"""``python -m dumbbell.cli ARGS`` runs the ``dumbbell`` command."""

import sys

from .app import main

sys.exit(main())
