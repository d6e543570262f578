//! The wire contract between the dressform host and the controller boards ("nodes") of the
//! robotic dress form. `no_std`; the `std` feature adds conveniences for the host.
#![cfg_attr(not(feature = "std"), no_std)]
