"""Seed 000's tipping judgment and recovery controller (pure-math pieces, no MuJoCo)."""
