"""ATHENA posture control vs simple control, and the gain sweep (README.md)."""
