"""Spectra, peaks, preprocessing and demodulation."""
