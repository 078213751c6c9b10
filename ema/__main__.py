"""``python -m ema``: the command line."""

import sys

from ema.cli.main import console

sys.exit(console())
