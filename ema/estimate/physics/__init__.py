"""The physics every kind's reading shares: η's search between its bounds (``eta_search``) and a sensor's noise read
off its own signal (``noise_reading``); each kind's own equations lie in its folder."""
