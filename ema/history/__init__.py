"""The history: every answered estimate, the actuators' documents and calibrations, behind one repository.

``open_history(setting)`` opens SQLite (a file path, the embedded default) or PostgreSQL (a
``postgresql://`` address, a ground station's shared history); the service, the fleet runner and
the command line all go through it.
"""
