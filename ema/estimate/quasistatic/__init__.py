"""A window logged under 1 kHz, or a stepper's at any rate, read with what its rate allows: Eq. 5.1 at constant
speed (``stretches``), the drive's current read as its kind's drive reads it (``drive``), a departure from the
healthy actuator judged either way (``departure``), the document written (``pipeline``)."""
