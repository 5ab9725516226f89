//! `dqhand metrics`: the realism metrics of LB, QB, DQB and CoR on one hand.

use std::path::PathBuf;
use std::sync::Arc;

use dqhand::engine::ModelSource;

/// Arguments of `dqhand metrics`.
#[derive(clap::Args)]
pub struct Args {
    /// A .glb or .gltf file with the WebXR hand joints, or `builtin`.
    #[arg(long, default_value = "builtin")]
    mesh: ModelSource,
    /// Print everything as one JSON object.
    #[arg(long, conflicts_with = "markdown")]
    json: bool,
    /// Print the headline numbers as a markdown table (as in the README).
    #[arg(long)]
    markdown: bool,
    /// Also write one CSV per sweep into this directory, for plotting.
    #[arg(long)]
    csv: Option<PathBuf>,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let model = args.mesh.load()?;
    crate::warn_all(&model.warnings);
    let report = dqhand::metrics::measure(Arc::new(model)).map_err(|e| e.in_file(args.mesh.to_string()))?;
    if let Err(why) = &report.closed {
        eprintln!("dqhand: warning: {}: volume is undefined: the mesh is not closed ({why}); the other metrics follow", args.mesh);
    }
    if let Some(dir) = &args.csv {
        report.write_csv(dir)?;
    }
    if args.json {
        println!("{}", report.to_json());
    } else if args.markdown {
        print!("{}", report.markdown());
    } else {
        println!("{}: {} vertices; LB, QB, DQB and CoR on {} sweeps", args.mesh, report.vertices, report.sweeps.len());
        let w = report.headline().iter().map(|h| h.0.chars().count()).max().unwrap_or(0);
        println!("{:<w$}  {:>9} {:>9} {:>9} {:>9}", "measure", "LB", "QB", "DQB", "CoR");
        for (label, v) in report.headline() {
            let [lb, qb, dqb, cor] = v.map(dqhand::metrics::format_value);
            println!("{label:<w$}  {lb:>9} {qb:>9} {dqb:>9} {cor:>9}");
        }
    }
    Ok(())
}
