"""``python -m rigedit`` runs the ``rigedit`` command."""
import sys

from .cli import main

sys.exit(main())
