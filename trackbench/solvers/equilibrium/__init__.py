"""The static equilibrium's numerical methods: Newton, Levenberg-Marquardt,
continuation, and small dense solves in a fixed order."""
