//! Spot frames, a simulated Spot, recordings and the navigator of spot-nav.
