"""Thermospheric density from satellite drag and meteoroid ablation (Close & Li 2015)."""
