"""Stage 1, prepare: a logged window made ready to be read, or refused naming the field (``conditioning``)."""
