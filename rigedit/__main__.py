"""``python -m rigedit`` runs the ``rigedit`` command."""
import sys

from .cli.main import main

sys.exit(main())
