//! Prints the DBC file for a form with nodes 1..=N (default 9, the reference form):
//!
//! ```sh
//! cargo run -p firmware-protocol --example dbc -- 12 > my-form.dbc
//! ```

use std::process::ExitCode;

fn main() -> ExitCode {
    let nodes = match std::env::args().nth(1).map(|n| n.parse::<u8>()) {
        None => 9,
        Some(Ok(n @ 1..=63)) => n,
        Some(_) => {
            eprintln!("usage: dbc [NODES]   (NODES in 1..=63, default 9)");
            return ExitCode::FAILURE;
        }
    };
    let mut dbc = String::new();
    firmware_protocol::dbc::write(&mut dbc, nodes).expect("writing to a String cannot fail");
    print!("{dbc}");
    ExitCode::SUCCESS
}
