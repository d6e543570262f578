//! dressform: personalized symmetric mannequins from 3D body scans (Hu et al., "Personalized
//! 3D Mannequin Reconstruction Based on 3D Scanning"), and the robotic dress form they drive.
//!
//! Modules follow the pipeline:
//! - [`body_model`]: the statistical body model (paper 3.1.1): PCA shape space, MVC joints, skinning, glTF;
//! - [`mesh`]: the one triangle-mesh type, its topology and components;
//! - [`scan`]: reading OBJ/PLY/STL, validation and cleaning, the canonical body frame;
//! - [`slice`]: horizontal cross-sections and their girths;
//! - [`regions`]: body regions and landmarks (crotch, armpits, neck) from tracked slices;
//! - [`segmented_body`]: a body segmented once, and its (cached) sections: what `measure`,
//!   `mannequin` and the comparisons take;
//! - [`symmetry`]: axial (torso) and bilateral (legs) symmetry of sections, girth preserved;
//! - [`fit`]: the body model fitted to a scan (eq. 4): pose and shape, robust ICP with LM;
//! - [`fitting`]: the robotic form's rings placed on the mannequin, set-points, fidelity;
//! - [`mannequin`]: the symmetric mannequin: layers, symmetry, watertight rebuild;
//! - [`measure`]: height, crotch height, chest/waist/hip girths; Table 1 and Fig. 11;
//! - [`reconstruct`]: pose symmetry first (fit, rig transfer, re-pose), then the mannequin;
//! - [`pipeline`]: one call per command: scan to mannequin, and to a form fitted to it;
//!   [`profiles`]: the `profiles.json` format; [`outputs`]: a result as its set of files;
//! - [`preview`]: pictures of a result: `preview.png` and `sections.svg`;
//! - [`report`]: what `dressform info` says about a scan;
//! - [`output`]: atomic file writes and all-or-nothing output sets;
//! - [`messages`]: how problems are worded (one bounded line each);
//! - [`setpoints`]: the set-point file (actuator id → extension, mm) the controller drives to;
//! - [`safety`]: [`safety::SafeTarget`], the only way a target reaches the wire;
//! - [`controller`]: the host controller: drives the robotic form over serial, slcan, SocketCAN or the simulated bus;
//! - [`makehuman`]: the CC0 MakeHuman assets (base mesh, targets, 163-bone rig, weights) and posing them;
//! - [`skinning`]: linear blend skinning (eq. 3) and its angle convention;
//! - [`pose_symmetry`]: the fitted pose made symmetric, the scan re-posed to it;
//! - [`rig_transfer`]: the fitted model's skin weights given to the scan.

pub mod body_model;
pub mod controller;
pub mod fit;
pub mod fitting;
pub mod input;
pub mod makehuman;
pub mod mannequin;
pub mod measure;
pub mod mesh;
pub mod messages;
pub mod output;
pub mod outputs;
pub mod pipeline;
pub mod pose_symmetry;
pub mod preview;
pub mod profiles;
pub mod reconstruct;
pub mod regions;
pub mod report;
pub mod rig_transfer;
pub mod safety;
pub mod scan;
pub mod segmented_body;
pub mod setpoints;
pub mod skinning;
pub mod slice;
pub mod symmetry;
