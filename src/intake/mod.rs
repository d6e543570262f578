//! Intake: scans processed unattended, as a capture pipeline delivers them. One mechanism,
//! [`process::Processor::process`] (scan in, `OUT/<customer>/` out, all or nothing, skipped
//! when made from the same input before), driven two ways: [`batch`] over a folder or a
//! manifest ([`jobs`]), sharded across cluster jobs ([`shard`]) with a [`summary`] per shard;
//! and [`watch`] over a folder as scans land, with a [`journal`] for restarts. A scanner's
//! [`landmarks`] file beside a scan is read and carried along. [`hash`] is the stable hash
//! of shards and input hashes.

pub mod batch;
pub mod hash;
pub mod jobs;
pub mod journal;
pub mod landmarks;
pub mod process;
pub mod shard;
pub mod summary;
pub mod watch;
