"""Verifier: simulate the machine's own interpolators on emitted code, in integer motor steps."""
