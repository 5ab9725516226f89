//! `dqhand hand`: build the anatomical hand for a user's measurements and write it rigged.

use std::path::PathBuf;

use dqhand::hand::{HandParams, Side, DEFAULT_VERTICES};

/// Arguments of `dqhand hand`.
#[derive(clap::Args)]
pub struct Args {
    /// Hand length, wrist crease to the tip of the middle finger (m).
    #[arg(long, default_value_t = 0.19)]
    length: f32,
    /// Hand breadth across the metacarpal heads (m).
    #[arg(long, default_value_t = 0.085)]
    breadth: f32,
    /// Which hand.
    #[arg(long, value_enum, default_value_t = SideArg::Right)]
    side: SideArg,
    /// Vertices of the mesh (level of detail), 1000 to 60000.
    #[arg(long, default_value_t = DEFAULT_VERTICES)]
    vertices: usize,
    /// Output: a rigged, skinned .glb with collision proxies on its joints.
    #[arg(long)]
    out: PathBuf,
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum SideArg {
    Left,
    Right,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let side = match args.side {
        SideArg::Left => Side::Left,
        SideArg::Right => Side::Right,
    };
    let params = HandParams { length: args.length, breadth: args.breadth, side, vertices: args.vertices };
    let model = dqhand::hand::build(&params)?;
    dqhand::io::write_skinned_glb(&model, &args.out)?;
    println!(
        "wrote {}: {} ({} triangles)",
        args.out.display(),
        model.description,
        model.mesh.triangle_count()
    );
    Ok(())
}
