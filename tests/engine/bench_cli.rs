//! `octovox bench … --quick` as a smoke run: every table is produced, for
//! every model, and written to the output folder. (Speed is measured by the
//! full bench, not by tests.)
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::process::Command;

#[test]
fn every_bench_runs_and_writes_its_tables() {
    let out = tempfile::tempdir().unwrap();
    for (kind, rows) in [
        ("build", &["torus64", "teapot256", "nefertiti512", "sculpture10M"][..]),
        ("edit", &["one voxel", "sphere r = 8", "sphere r = 32"][..]),
        ("render", &["torus64", "teapot256", "nefertiti512", "sculpture10M"][..]),
        ("scale", &["64", "128"][..]),
        ("scene", &["frame ms", "pool bytes (models, CPU)", "pool bytes (drawn, GPU)", "load ms"][..]),
    ] {
        let run = Command::new(env!("CARGO_BIN_EXE_octovox"))
            .args(["bench", kind, "--quick", "--out"])
            .arg(out.path())
            .output()
            .unwrap();
        assert!(run.status.success(), "bench {kind}: {}", String::from_utf8_lossy(&run.stderr));
        let md = std::fs::read_to_string(out.path().join(format!("{kind}.md"))).unwrap();
        let json = std::fs::read_to_string(out.path().join(format!("{kind}.json"))).unwrap();
        for row in rows {
            assert!(md.contains(&format!("| {row} |")), "bench {kind}: no row {row}\n{md}");
        }
        assert!(json.trim_start().starts_with('['), "{json}");
    }
}

#[test]
fn specialised_kernels_draw_the_same_images_as_the_full_one() {
    let out = tempfile::tempdir().unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["bench", "effects", "--quick", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("effects.json")).unwrap()).unwrap();
    let md = std::fs::read_to_string(out.path().join("effects.md")).unwrap();
    for row in ["terrain (diffuse only)", "showroom (mixed)", "interior (emissive, closed)"] {
        assert!(md.contains(&format!("| {row} |")), "no row {row}\n{md}");
    }
    let rows = json.as_array().unwrap();
    assert_eq!(rows.len(), 3);
    for row in rows {
        assert_eq!(row["pixels_differing"], 0, "{row}");
    }
    assert_eq!(rows[0]["effects_auto"], serde_json::json!(["sun", "sky"]));
    assert_eq!(rows[2]["effects_auto"], serde_json::json!(["sun", "sky", "emit"]));
}

#[test]
fn the_quality_bench_measures_every_knob_and_plots_them() {
    let out = tempfile::tempdir().unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["bench", "quality", "--quick", "--out"])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let md = std::fs::read_to_string(out.path().join("quality.md")).unwrap();
    for knob in [
        "| base |",
        "| --spp |",
        "| --bounces |",
        "| --shadow-samples |",
        "| --render-scale |",
        "| --mode |",
        "| --lod |",
    ] {
        assert!(md.contains(knob), "no row {knob}\n{md}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.path().join("quality.json")).unwrap()).unwrap();
    let rows = json["knobs"].as_array().unwrap();
    // The filter's change to each reference in standard errors: positive,
    // and not far above noise (the scenes' figures are in docs/bench).
    for row in json["denoised_reference"].as_array().unwrap() {
        let rms = row["change"]["rms"].as_f64().unwrap_or(-1.0);
        assert!(rms > 0.0 && rms < 3.0, "{row}");
    }
    // The level of detail alone: exact at 0, and it changes the picture no
    // more as the footprint shrinks.
    let lod = json["level_of_detail"].as_array().unwrap();
    assert_eq!(lod.len(), 5);
    assert_eq!((lod[0]["lod"].as_f64(), lod[0]["flip"].as_f64()), (Some(0.0), Some(0.0)));
    let changed: Vec<f64> = lod.iter().map(|r| r["changed_pixels"].as_f64().unwrap()).collect();
    assert!(changed.windows(2).all(|w| w[0] <= w[1]), "{changed:?}");
    assert!(changed[4] > 0.0, "lod 8 changed nothing: {changed:?}");
    assert!(rows.iter().all(|r| r["flip"].as_f64().is_some_and(|f| (0.0..=1.0).contains(&f))), "{rows:?}");
    assert!(rows.iter().any(|r| r["pareto"] == true));
    // Fewer bounces cannot be closer to an 8-bounce reference on average than more.
    let flip_of = |knob: &str, value: &str| {
        let values: Vec<f64> = rows
            .iter()
            .filter(|r| r["knob"] == knob && r["value"] == value)
            .map(|r| r["flip"].as_f64().unwrap())
            .collect();
        values.iter().sum::<f64>() / values.len() as f64
    };
    assert!(flip_of("--bounces", "0") > flip_of("--bounces", "6"));
    let png = image::open(out.path().join("quality.png")).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), (1100, 700));
    let coloured = png.pixels().filter(|p| p[0] != p[1] || p[1] != p[2]).count();
    assert!(coloured > 500, "the plot has hardly any coloured pixels: {coloured}");
}

/// Issue 27, bug 5: `octovox bench` run from a checkout, as the README
/// says, rewrote the committed docs/bench/; its default is a build folder.
#[test]
fn bench_without_out_leaves_the_committed_tables_alone() {
    let checkout = tempfile::tempdir().unwrap();
    let committed = checkout.path().join("docs/bench/edit.md");
    std::fs::create_dir_all(committed.parent().unwrap()).unwrap();
    std::fs::write(&committed, "the committed table\n").unwrap();
    let run = Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["bench", "edit", "--quick"])
        .current_dir(checkout.path())
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    assert_eq!(std::fs::read_to_string(&committed).unwrap(), "the committed table\n");
    assert!(checkout.path().join("target/bench/edit.md").is_file());
}
