//! SE(3)/SE(2) pose-graph optimisation (Gauss-Newton, Levenberg-Marquardt) and g2o files for spot-nav.
