"""Maneuver detectors on ground tracking: the batch GLR test and Kaderali's Ψ/K filter
(Kaderali 2021)."""
