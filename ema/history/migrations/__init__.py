"""Alembic migrations of the history (``ema.history.schema`` runs them)."""
