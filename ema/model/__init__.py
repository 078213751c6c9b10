"""The documents every layer reads and the facts they rest on: the actuator document and its kinds' sections, the
window, the log maps and log files, the kinds' facts, bounds and units, and the thread budget the kernels share.
Nothing here simulates or estimates: each kind's simulator lives in its folder under ``ema.kinds``."""
