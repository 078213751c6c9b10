"""Entry points: the ``ema`` command line (and, as they land, the replay client and benchmarks)."""
