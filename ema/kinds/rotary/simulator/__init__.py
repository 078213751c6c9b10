"""The rotary kind's simulator: the thesis's EMA, its aircraft and its sensors, in Numba."""
