"""Prognostics: an actuator's history of estimates as a trend and a remaining useful life."""
