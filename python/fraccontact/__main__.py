"""python -m fraccontact COMMAND ...: the console command (fraccontact.cli)."""

import sys

from .cli import main

sys.exit(main())
