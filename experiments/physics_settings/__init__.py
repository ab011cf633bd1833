"""Physics settings per robot: speed against the fidelity rows (README.md)."""
