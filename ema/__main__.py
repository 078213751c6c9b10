"""``python -m ema``: the command line."""

import sys

from ema.cli.main import main

sys.exit(main())
