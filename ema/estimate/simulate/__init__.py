"""Stage 3, simulate, as every kind draws it: a box around the physics estimate, filled by a scrambled Halton
sequence (``design``); each kind's own dataset lies in its folder."""
