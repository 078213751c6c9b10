"""What a window shows beyond the actuator's model, read in turn (``read``): a sensor off zero, the drive's
k_T and J_M, the hinge moment's gain against its loads and against the aircraft, the viscous coefficient."""
