"""The physics every stage reads a window with: Eq. 5.1's residual torque and its least-squares solution, the
window's own scenario simulated at a health, its sensors' noise, and FSJ at a break-away."""
