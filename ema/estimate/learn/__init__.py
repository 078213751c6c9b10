"""Stage 4, learn: the shallow network of the thesis, trained on the window's dataset."""
