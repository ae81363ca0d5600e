"""Lubrication: rheology, roughness, thermal kernels, friction models and the EHL solver."""
