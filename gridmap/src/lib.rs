//! Map cloud to 2D occupancy grid, inflation and map files for spot-nav.
