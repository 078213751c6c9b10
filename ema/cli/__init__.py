"""Entry points: the ``ema`` command line, the replay client, the fleet runner, the benchmark, the figures."""
