"""Cleaning stages applied to momentum before detection (masks, comb filter, trend removal)."""
