//! Point cloud registration backends (ICP, point-to-plane ICP, LOAM features) for spot-nav.
