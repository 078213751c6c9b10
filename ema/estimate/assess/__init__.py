"""Stage 5, assess: both estimators scored on held-out simulations and blended, and the answer checked by
simulating the window at it."""
