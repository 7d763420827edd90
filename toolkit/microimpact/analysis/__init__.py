"""Analysis: what is learned from measurements.

- :mod:`.fitting`: zeta_H, zeta_A (and optionally w_A) fitted to measured e_n(v_n) with lmfit.
- :mod:`.fit_result`: the fit's result record (:class:`DampingFit`), its NetCDF form and its
  formatter; reading a fit needs no lmfit.
- :mod:`.flags`: which measurements unmeasured spin, angle error or closeness to capture make
  unreliable.
- :mod:`.kharaz`: the model against the Kharaz et al. (2001) oblique-impact measurements.
- :mod:`.synthetic`: labelled synthetic measurements from stated parameters.
"""
