//! Simulations that stand in for hardware in tests, CI and the demo.
