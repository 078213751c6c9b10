"""The HTTP service: a thin FastAPI shell over ``ema.kinds.rotary.pipeline``."""
