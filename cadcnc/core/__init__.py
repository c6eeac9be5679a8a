"""The core stage: the error tree and exit codes, tolerances, units, work limits, the typed
Job, JSON-ready values, interrupts and the trim-grid reader. Imports nothing else of cadcnc."""
