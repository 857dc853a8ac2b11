//! Grid path planners (Dijkstra, A*, JPS, JPS+) and Moving AI benchmark IO for spot-nav.
