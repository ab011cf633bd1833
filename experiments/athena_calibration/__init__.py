"""Joint calibration of the ATHENA model against rows 8-11 of the reproduction (README.md)."""
