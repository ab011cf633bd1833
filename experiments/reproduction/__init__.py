"""The reproduction of the three papers' headline numbers (README.md)."""
