"""The HTTP service: a FastAPI shell over the kinds' registry (``ema.kinds``): it parses the documents, asks each
window's kind for its answer within the settings' limits, and stores it in the history."""
