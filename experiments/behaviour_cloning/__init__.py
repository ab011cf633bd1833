"""Behaviour cloning of the analytical controllers, a candidate warm start for PPO (README.md)."""
