//! `dressform status [--form <form.toml>] (--sim | --serial <path> | --slcan <path> |
//! --can <iface>) [--json]`: every node's identity, state, faults and positions, without
//! changing anything. With `--sim`, of a simulated form started for this command (fresh:
//! Disabled, not homed); `dressform sim` serves one that lasts.

use std::time::Duration;

use dressform::form::controller::simulated::SimConfig;
use dressform::form::controller::{LinkSpec, NodeReport, status};

use super::Failure;
use super::link::{self, FormArg, LinkArgs, runtime};

/// How long to listen for heartbeats and feedback.
const LISTEN: Duration = Duration::from_millis(300);

#[derive(Debug, clap::Args)]
pub struct StatusArgs {
    #[command(flatten)]
    form: FormArg,
    #[command(flatten)]
    link: LinkArgs,
    /// Print JSON on standard output.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &StatusArgs) -> Result<(), Failure> {
    let form = args.form.load()?;
    let spec = args.link.spec();
    let reports = runtime()?.block_on(async {
        let owned = link::own(&spec, &form, &SimConfig::default())?;
        status(owned.connection, &form, LISTEN).await.map_err(Failure::other)
    })?;
    if spec == LinkSpec::Sim && !args.json {
        outln!(
            "a simulated form started for this command (fresh; `dressform sim` serves one that lasts):"
        );
    }
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&reports).map_err(Failure::other)?);
    } else {
        print(&reports);
    }
    Ok(())
}

fn print(reports: &[NodeReport]) {
    for r in reports {
        let state = r.state.as_deref().unwrap_or("silent");
        let version = match (&r.protocol, &r.firmware) {
            (Some(p), Some(f)) => format!("protocol {p}, firmware {f}"),
            _ => "not identified".into(),
        };
        let faults = match &r.fault_words {
            Some(words) => format!(", faults {} ({words})", r.faults.join("|")),
            None => String::new(),
        };
        outln!("node {}: {state} ({version}){faults}", r.node);
        for problem in &r.problems {
            outln!("  problem: {problem}");
        }
        for (id, mm) in &r.positions_mm {
            let p = mm.map_or_else(|| "unknown".to_string(), |v| format!("{v:.2} mm"));
            outln!("  {id:<18} {p}");
        }
    }
}
