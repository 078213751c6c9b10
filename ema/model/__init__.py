"""Numba physics of the elevator EMA: parameters, aircraft, commands, kernels, batch API."""
