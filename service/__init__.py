"""The HTTP service: a thin FastAPI shell over ``training.pipeline``."""
