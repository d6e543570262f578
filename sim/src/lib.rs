//! Simulations that stand in for hardware in tests, CI and the demo.
//!
//! - [`capture`]: synthetic body scans with known ground truth, and scanner artifacts.

pub mod capture;
