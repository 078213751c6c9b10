"""An independent implementation of the actuator model (``docs/model.md``), for tests and benchmarks only.

Nothing here imports ``sim``: windows drawn by this package are what "data our own code did not
generate" means in this repository (see the developers' guide).
"""
