"""Identification: fn, zeta, FRFs and modes from measurements."""
