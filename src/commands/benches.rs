//! `octovox bench KIND`: runs one bench, prints its table and writes it to
//! `--out` (target/bench/ unless told; the committed tables are
//! docs/bench/) as markdown and JSON.

use std::process::ExitCode;

use anyhow::Context;

use crate::cli::{BenchArgs, BenchKind};

pub fn run(args: &BenchArgs) -> anyhow::Result<ExitCode> {
    if args.lod > 0.0 && args.what != BenchKind::Render {
        anyhow::bail!("--lod is for `bench render`; `bench quality` measures several levels of detail itself");
    }
    let (markdown, json) = match args.what {
        BenchKind::Build => super::bench::bench_build(args.quick)?,
        BenchKind::Edit => super::bench::bench_edit(args.quick)?,
        BenchKind::Render => super::bench::bench_render(args.quick, args.lod)?,
        BenchKind::Effects => super::bench_effects::bench_effects(args.quick)?,
        BenchKind::Quality => super::bench_quality::bench_quality(args.quick, &args.out)?,
        BenchKind::Scale => super::bench_scale::bench_scale(args.quick)?,
        BenchKind::Scene => super::bench_scene::bench_scene(args.quick)?,
        BenchKind::Anim => super::bench_anim::bench_anim(args.quick)?,
    };
    say!("{markdown}")?;
    let mut name = format!("{:?}", args.what).to_lowercase();
    if args.lod > 0.0 {
        // Beside the exact table, not over it.
        name += &format!("-lod{}", args.lod);
    }
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    for (ext, text) in [("md", markdown), ("json", json)] {
        let path = args.out.join(format!("{name}.{ext}"));
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}
