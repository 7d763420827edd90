"""The experiment design's defaults, in a module that imports nothing.

:mod:`microimpact.analysis.design` uses them; the command line prints them in its help (which must
not wait for scipy and pandas to import, as :mod:`~microimpact.analysis.sampling_defaults`) and the
pipeline's ``design`` rule passes only what its config gives, so each default lives here once.

Examples
--------
>>> from microimpact.analysis.design import DesignSpace, design_next_impacts
>>> import inspect
>>> inspect.signature(design_next_impacts).parameters["n"].default == DEFAULT_NEW_IMPACTS
True
>>> DesignSpace(radii=(1e-6,)).oblique_quantity == DEFAULT_OBLIQUE_QUANTITY
True
"""

__all__ = ["DEFAULT_NEW_IMPACTS", "DEFAULT_NEW_OBLIQUE", "DEFAULT_PARAMETERS", "OBLIQUE_QUANTITIES",
           "DEFAULT_OBLIQUE_QUANTITY", "DEFAULT_E_T_SIGMA", "DEFAULT_REBOUND_ANGLE_SIGMA", "DEFAULT_REBOUND_SPIN_SIGMA"]

#: new e_n impacts of a design (a day or two of a measurement campaign at one size class)
DEFAULT_NEW_IMPACTS = 20
#: new oblique impacts of a friction design
DEFAULT_NEW_OBLIQUE = 6
#: the parameters a design narrows when none are named
DEFAULT_PARAMETERS = ("zeta_hertz",)
#: what a laboratory may measure of an oblique impact besides e_n (the measured-impact columns of
#: data/README.md), with the unit of the column and of its uncertainty; "none": e_n only
OBLIQUE_QUANTITIES = {"tangential_restitution": "1", "rebound_angle": "deg", "rebound_spin": "rad/s", "none": ""}
#: the oblique quantity measured when none is named
DEFAULT_OBLIQUE_QUANTITY = "tangential_restitution"
#: standard uncertainty of a measured tangential restitution (that of e_n in the bundled synthetic
#: data: both are ratios of speeds read from the same high-speed video). [-]
DEFAULT_E_T_SIGMA = 0.02
#: standard uncertainty of a measured rebound angle: about one degree, the resolution of a
#: trajectory read from a few video frames. [deg]
DEFAULT_REBOUND_ANGLE_SIGMA = 1.0
#: standard uncertainty of a measured rebound spin (a few % of the ~1e6 rad/s of a rolling
#: 7 um sphere at 10 m/s, v_t / R). [rad/s]
DEFAULT_REBOUND_SPIN_SIGMA = 1.0e5
