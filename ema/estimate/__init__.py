"""From simulations to estimates: preprocessing, datasets, the shallow network, estimators."""
