"""Figures and animations of studies and runs."""
