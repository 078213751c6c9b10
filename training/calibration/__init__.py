"""Close the loop: residuals between measured and simulated windows, traced to a missing effect."""
