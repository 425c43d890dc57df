"""Scenario texts shared by the scenario-file tests."""

#: The smallest complete hand-written arm.
MINIMAL = """
[rod]
length = 0.3
radius = 0.01

[material]
E = 1e5
nu = 0.5
mu = 10.0
rho = 1000.0

[solver]
t_end = 1.0
"""
