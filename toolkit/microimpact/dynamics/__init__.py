"""Nonlinear dynamics of the normal contact, Eqs. (28)-(38) of Cheng, Brach & Dunn (2002).

Jacobian and equilibria, their classification, the critical velocity (Eq. (38)), the asymptotic
frequency (Eq. (37)), the capture velocity, phase portraits and the bifurcation plane.
"""

from microimpact.dynamics.nonlinear import *  # noqa: F401,F403  (the public names of nonlinear)
from microimpact.dynamics.nonlinear import __all__  # noqa: F401
