"""The physics a rotary window is read with: Eq. 5.1's residual torque and its least-squares solution
(``friction``, with its features and its sensors' shifts), the window's own scenario simulated at a health
(``scenario``), and FSJ at a break-away (``static_friction``)."""
