//! `dressform sim [--form <form.toml>] (--serial-pty | --slcan-pty) [--log <file>]
//! [--faults <spec>]`: a simulated robotic form on a pseudo-terminal, until Ctrl-C.

use super::Failure;
use super::link::FormArg;
use form_sim::serve::{PtyLink, ServeConfig, ServeError, run_until_ctrl_c};
use std::io::Write;
use std::path::PathBuf;

#[derive(Debug, clap::Args)]
#[command(group = clap::ArgGroup::new("link").required(true))]
pub struct ServeArgs {
    #[command(flatten)]
    form: FormArg,
    /// Speak the serial mapping (COBS + CRC) on a pseudo-terminal.
    #[arg(long, group = "link")]
    serial_pty: bool,
    /// Speak slcan (Lawicel ASCII, as USB-CAN adapters do) on a pseudo-terminal.
    #[arg(long, group = "link")]
    slcan_pty: bool,
    /// Write a candump log of all bus traffic to this file.
    #[arg(long)]
    log: Option<PathBuf>,
    /// Faults to inject, e.g. `drop=0.05,corrupt=0.01,node3:reboot@1.5s,chest-l1:stall@2s`
    /// (grammar in sim/form-sim/README.md).
    #[arg(long)]
    faults: Option<String>,
}

pub fn run(args: &ServeArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let faults = args
        .faults
        .as_deref()
        .unwrap_or("")
        .parse()
        .map_err(|e| Failure::bad_input(format!("--faults: {e}")))?;
    let transport = if args.serial_pty { PtyLink::SerialPty } else { PtyLink::SlcanPty };
    let mut config = ServeConfig::new(form, transport);
    config.log = args.log.clone();
    config.faults = faults;
    run_until_ctrl_c(config, |device| {
        outln!("{}", device.display());
        let _ = std::io::stdout().flush();
        errln!("simulated form ready on {} (Ctrl-C to stop)", device.display());
    })
    .map_err(|e| match e {
        ServeError::Sim(_) => Failure::bad_input(e),
        _ => Failure::other(e),
    })
}
