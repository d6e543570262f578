//! Pose symmetry (paper section 3.1): the statistical body model, fitted to the scan (eq. 4);
//! the scan takes the model's rig and is re-posed symmetric by linear blend skinning (eq. 3).

pub mod body_model;
pub mod makehuman;
pub mod model_fit;
pub mod pose_symmetry;
pub mod rig_transfer;
pub mod skinning;
