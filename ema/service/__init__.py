"""The HTTP service: a thin FastAPI shell over ``ema.estimate.pipeline``."""
