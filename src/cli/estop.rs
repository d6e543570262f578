//! `dressform estop (--serial <path> | --slcan <path> | --can <iface>)`: broadcast an
//! emergency stop. Every node stops at its acceleration limit, powers off and latches
//! `EMERGENCY_STOP` until a FaultReset (which the next `dressform drive` sends).

use super::Failure;
use super::drive::runtime;
use dressform::controller::{Connection, LinkSpec, emergency_stop};
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
#[group(required = true, multiple = false, id = "link")]
pub struct EstopArgs {
    /// A serial port speaking the protocol's serial mapping.
    #[arg(long, value_name = "PATH", group = "link")]
    serial: Option<PathBuf>,
    /// An slcan adapter on a serial port.
    #[arg(long, value_name = "PATH", group = "link")]
    slcan: Option<PathBuf>,
    /// A SocketCAN interface.
    #[arg(long, value_name = "IFACE", group = "link")]
    can: Option<String>,
}

pub fn run(args: &EstopArgs) -> Result<(), Failure> {
    let spec = match (&args.serial, &args.slcan, &args.can) {
        (Some(p), _, _) => LinkSpec::Serial(p.clone()),
        (_, Some(p), _) => LinkSpec::Slcan(p.clone()),
        (_, _, Some(i)) => LinkSpec::Can(i.clone()),
        _ => return Err(Failure::bad_input("name the link: --serial, --slcan or --can")),
    };
    runtime()?.block_on(async {
        let connection = Connection::open(&spec).map_err(Failure::other)?;
        emergency_stop(connection).await.map_err(Failure::other)
    })?;
    errln!("emergency stop sent");
    Ok(())
}
