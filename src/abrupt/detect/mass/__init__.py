"""Mass-property change detectors on inertia tracks (Dabrowski 2003; Harris et al. 2025 §3.1-3.2)."""
