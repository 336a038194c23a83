"""What residual sensor errors cost in navigation: strapdown integration and error growth.

(Being built for issue 16: the strapdown integrator, the seed's closed-form error growth for the
static low-speed case, a Monte Carlo through the integrator, and the noise-model experiment.)
"""
