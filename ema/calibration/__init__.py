"""Close the loop: trace what the model misses in measured windows to an effect, add it, re-estimate."""
