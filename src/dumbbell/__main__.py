"""``python -m dumbbell ARGS`` runs the ``dumbbell`` command."""

import sys

from .cli.app import main

sys.exit(main())
