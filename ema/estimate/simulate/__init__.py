"""Stage 3, simulate: the window's own dataset, its health drawn in a box around the physics estimate."""
