"""The model: what the physics is, each formula written once.

- :mod:`.contact`: the :class:`Contact` record and what follows from it (mass, Eq. (7) w_A -> f0,
  the scales X and T of Eqs. (29)-(30), the zeta -> C conversion of Eqs. (14)-(15)).
- :mod:`.law`: the normal contact law, Eqs. (1)-(6) and (27): forces, potential energy, damping,
  dissipation, the twist friction torque; in SI and in the nondimensional form the solvers use.
- :mod:`.parameters`: the paper's parameter sets (Table 1 rows, Table 2 cases), defined once.
- :mod:`.kinematics`: incident velocity, slip velocity and the impact coefficients, Eqs. (21)-(25).
- :mod:`.tangential`: the closed-form tangential and rotational map of a homogeneous sphere.
- :mod:`.reduction`: the nondimensional groups of the normal impact of each law, and a contact with
  given groups.

Nothing here integrates anything; the solvers do.
"""
