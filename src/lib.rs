//! dressform: personalized symmetric mannequins from 3D body scans (Hu et al., "Personalized
//! 3D Mannequin Reconstruction Based on 3D Scanning"), and the robotic dress form they drive.
//!
//! The modules are grouped in wings that follow the pipeline, scan in to form out:
//!
//! 1. [`body`]: the scanned body as geometry: [`body::mesh`] (the one triangle-mesh type),
//!    [`body::scan`] (reading OBJ/PLY/STL, cleaning, the canonical frame), [`body::slice`]
//!    (cross-sections and girths), [`body::regions`] (crotch, armpits, neck from tracked
//!    slices) and [`body::segmented_body`] (a body segmented once, with its cached sections).
//! 2. [`pose`]: pose symmetry (paper 3.1): [`pose::body_model`] (PCA shape space, MVC joints,
//!    eq. 1-3), [`pose::makehuman`] (the CC0 assets it is built from), [`pose::skinning`] (linear
//!    blend skinning, eq. 3), [`pose::model_fit`] (the model fitted to a scan, eq. 4),
//!    [`pose::rig_transfer`] (the scan takes the model's rig) and [`pose::pose_symmetry`] (the
//!    scan re-posed symmetric).
//! 3. [`shape`]: shape symmetry (paper 3.2-3.3): [`shape::symmetry`] (axial and bilateral
//!    sections, eq. 5-12), [`shape::mannequin`] (layers, symmetry, the watertight rebuild),
//!    [`shape::measure`] (tailor's measurements, Table 1, Fig. 11) and [`shape::profiles`] (the
//!    `profiles.json` the form consumes).
//! 4. [`form`]: the robotic form: [`form::form_fit`] (its rings placed on the mannequin, with
//!    their fidelity), [`form::setpoints`] (the set-point file), [`form::safety`] (the only way a
//!    target reaches the wire) and [`form::controller`] (the host: serial, slcan, SocketCAN or the
//!    simulated bus, and the e-stop).
//! 5. [`run`]: one call per command and its results: [`run::pipeline`], [`run::reconstruct`]
//!    (pose symmetry, then the mannequin), [`run::outputs`] (a result as its set of files),
//!    [`atomic_output`] (all-or-nothing writes), [`run::preview`] (`preview.png`,
//!    `sections.svg`), [`run::report`] (`report.html`, the customer report) and [`run::info`]
//!    (what `dressform info` says about a scan).
//!
//! 6. [`intake`]: many scans unattended: `batch` (a folder or manifest, sharded on a cluster)
//!    and `watch` (a folder as scans land), one per-scan function for both.
//!
//! Used by all of them: [`messages`] (how a problem is worded: one bounded line) and [`input`]
//! (reading the JSON files a user hands in).

pub mod atomic_output;
pub mod body;
pub mod form;
pub mod input;
pub mod intake;
pub mod messages;
pub mod pose;
pub mod run;
pub mod shape;
