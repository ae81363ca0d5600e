"""Spur gear pair: definition, geometry, tip relief, tooth stiffness, load sharing, mesh cycle."""
