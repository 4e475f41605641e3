"""``python -m gcs_sysid`` runs the CLI."""

import sys

from .cli import main

sys.exit(main())
