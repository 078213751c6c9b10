"""The fleet's fork server, as a program: the module ``ema.cli.pool`` has it load first thing in its process (its
preload), run as a ``__main__`` is. It sets the cyclic collector for a program that loads many long-lived
modules (``ema.model.collector``), then loads the pipeline's and the kernels' modules, which every worker forked
from the server holds from its start. Importing it does both, so nothing else imports it.
"""

from ema.model.collector import collect_less_often

collect_less_often()

import ema.estimate.pipeline  # noqa: E402  (after the collector is set: the point of this module)
import ema.kinds.remote  # noqa: E402, F401
