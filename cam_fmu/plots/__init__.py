"""Figures (matplotlib, Agg backend): motion laws and cam programs, scenes."""
