"""Per-gait-cycle posture gains: the one-cycle look-ahead and its distillation (README.md)."""
