"""The fleet's fork server, as a program: the module ``ema.cli.pool`` has it load first thing in its process (its
preload), run as a ``__main__`` is. It sets the cyclic collector for a program that loads many long-lived
modules (``ema.model.collector``), loads the pipeline's and the kernels' modules, then warms the kernels on one
thread (``ema.kinds.remote.warm``): every worker forked from the server holds them from its start, loaded once
while the driver still reads the archive, not once per worker after it. One thread: the warm-up runs inline, so
no pool thread exists to be forked. It dies with the command that started it (``ema.cli.lifeline``), and so does
each worker with it. Importing it does all this, so nothing else imports it.
"""

from ema.cli.lifeline import die_with_parent
from ema.model.collector import collect_less_often

die_with_parent()  # with the command that started it: a kill -9 of it leaves nothing running
collect_less_often()

from ema.kinds import load_methods  # noqa: E402  (after the collector is set: the point of this module)
from ema.kinds.remote import warm  # noqa: E402

load_methods()

warm(1)
