//! One call per command and what it leaves behind: the pipeline, the reconstruction with pose
//! symmetry, the output set, the pictures, the customer report (`report.html`), and the scan
//! report of `dressform info`.

pub mod info;
pub mod outputs;
pub mod pipeline;
pub mod preview;
pub mod reconstruct;
pub mod report;
