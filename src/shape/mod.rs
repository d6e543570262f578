//! Shape symmetry (paper sections 3.2-3.3) and what is measured on it: symmetric sections with
//! their girths preserved, the watertight mannequin, the tailor's measurements, and the slice
//! profiles the robotic form takes.

pub mod mannequin;
pub mod measure;
pub mod profiles;
pub mod symmetry;
