//! `octovox replay` as a user runs it: every script in tests/replays passes,
//! failures name their line, bad scripts get clear errors and no panic.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn octovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().expect("run octovox")
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn replays() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/replays")
}

fn scripts() -> Vec<String> {
    let mut scripts: Vec<String> = std::fs::read_dir(replays())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "ovr"))
        .map(|p| p.display().to_string())
        .collect();
    scripts.sort();
    assert!(scripts.len() >= 8, "{scripts:?}");
    scripts
}

#[test]
fn every_script_passes_on_the_gpu() {
    std::fs::create_dir_all(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/out")).unwrap();
    let scripts = scripts();
    // tests/out is scratch space: what an earlier run left there may be replaced.
    let mut args = vec!["replay", "--force"];
    args.extend(scripts.iter().map(String::as_str));
    let out = octovox(&args);
    let text = stdout(&out);
    assert!(out.status.success(), "{text}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.lines().last().unwrap().ends_with(" 0 failed"), "{text}");
}

#[test]
fn every_script_passes_on_the_cpu() {
    std::fs::create_dir_all(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/out")).unwrap();
    let scripts = scripts();
    let mut args = vec!["replay", "--cpu", "--force"];
    args.extend(scripts.iter().map(String::as_str));
    let out = octovox(&args);
    assert!(out.status.success(), "{}", stdout(&out));
}

fn run_script(text: &str) -> (Output, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.ovr");
    std::fs::write(&path, text).unwrap();
    let out = octovox(&["replay", "--cpu", path.to_str().unwrap()]);
    let text = stdout(&out) + &String::from_utf8_lossy(&out.stderr);
    (out, text)
}

#[test]
fn a_failing_expectation_names_its_line_and_fails_the_run() {
    let (out, text) = run_script("new\ncolor 4\nplace 1 2 3\nexpect voxel 1 2 3 5\nexpect count 1\n");
    assert!(!out.status.success());
    assert!(text.contains("bad.ovr:4: expected voxel [1, 2, 3] = 5, got 4"), "{text}");
    assert!(text.contains("replay: 1 passed, 1 failed"), "{text}");
}

#[test]
fn bad_scripts_get_clear_errors_with_the_line() {
    let cases = [
        ("new\nplcae 1 2 3\n", "unknown command 'plcae' at", ":2:1"),
        ("place 1 2\n", "missing Z at", ":1:10"),
        ("color 0\n", "palette index 0 is outside 1..=255", ":1:7"),
        ("color 300\n", "palette index 300 is outside 1..=255", ":1:7"),
        ("brush sphere -1\n", "sphere radius -1 is outside 0..=4096", ":1:14"),
        ("brush sphere 1000000000\n", "sphere radius 1000000000 is outside", ":1:14"),
        ("load does-not-exist.vox\n", "does-not-exist.vox", ":1"),
        ("new\nplace 99999999 0 0\n", "X 99999999 is outside", ":2:7"),
        ("new\nundo\n", "nothing to undo", ":2"),
        ("new\nexpect written <= 10\n", "needs an edit line", ":2"),
    ];
    for (script, message, place) in cases {
        let (out, text) = run_script(script);
        assert!(!out.status.success(), "{script:?} should fail");
        assert!(text.contains(message) && text.contains(place), "{script:?}: {text}");
        assert!(!text.contains("panicked"), "{script:?}: {text}");
    }
}

#[test]
fn a_missing_script_file_is_an_error_not_a_panic() {
    let out = octovox(&["replay", "--cpu", "/nonexistent/script.ovr"]);
    let text = stdout(&out);
    assert!(!out.status.success());
    assert!(text.contains("cannot read script"), "{text}");
}

/// Runs a script on the GPU or the CPU (letting it replace what an earlier
/// run wrote) and checks that it passes with `summary`.
fn replay_passes(script: &Path, cpu: bool, summary: &str) {
    let mut args = vec!["replay", "--force"];
    if cpu {
        args.push("--cpu");
    }
    args.push(script.to_str().unwrap());
    let out = octovox(&args);
    let text = stdout(&out);
    assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
    assert!(text.contains(summary), "{text}");
}

#[test]
fn the_effect_set_follows_edits_and_undo() {
    // A diffuse scene whose palette also holds a glass entry (index 9).
    let dir = tempfile::tempdir().unwrap();
    let mut scene = octovox::scene::Scene::default();
    let mut glass = octovox::scene::Material::new(octovox::scene::MaterialKind::Glass);
    glass.params.insert("_ri".into(), "1.5".into());
    scene.palette.materials[9] = glass;
    scene.apply_brush(&octovox::scene::Shape::Voxel(glam::IVec3::ZERO), octovox::scene::Op::Place(3)).unwrap();
    let vox = dir.path().join("diffuse.vox");
    octovox::io::save_scene(&vox, &scene, Default::default()).unwrap();
    let script = "load diffuse.vox\nexpect effects sun sky\ncolor 9\nplace 0 1 0\nexpect effects sun sky glass\n\
                  undo\nexpect effects sun sky\nredo\nremove 0 1 0\nexpect effects sky sun\n";
    let path = dir.path().join("effects.ovr");
    std::fs::write(&path, script).unwrap();
    for cpu in [false, true] {
        replay_passes(&path, cpu, "4 passed, 0 failed");
    }
    // A wrong expectation fails with both sets named.
    std::fs::write(&path, "load diffuse.vox\nexpect effects sun sky glass\n").unwrap();
    let out = octovox(&["replay", "--cpu", path.to_str().unwrap()]);
    let text = stdout(&out);
    assert!(!out.status.success());
    assert!(text.contains("expected effects [sun sky glass], got [sun sky]"), "{text}");
}

#[test]
fn palette_edits_are_undoable_change_the_effects_and_are_saved() {
    let dir = tempfile::tempdir().unwrap();
    let script = "new\ncolor 9\nplace 0 0 0\nexpect effects sun sky\n\
                  material 9 glass _ri 1.5 _trans 1\nexpect effects sun sky glass\n\
                  rgb 9 10 20 30\nundo 2\nexpect effects sun sky\nredo 2\nexpect effects sun sky glass\nsave out.vox\n";
    let path = dir.path().join("palette.ovr");
    std::fs::write(&path, script).unwrap();
    for cpu in [false, true] {
        replay_passes(&path, cpu, "4 passed, 0 failed");
        let scene = octovox::io::load_scene(&dir.path().join("out.vox"), 0).unwrap();
        assert_eq!(scene.palette.color(9), [10, 20, 30, 255]);
        let material = scene.palette.material(9);
        assert_eq!(material.kind, octovox::scene::MaterialKind::Glass);
        assert_eq!((material.ior(), material.transparency()), (1.5, 1.0));
    }
    // Bad palette lines name their line and column.
    for (line, message) in [
        ("material 9 velvet", "expected diffuse, metal, glass, emit or media, found 'velvet'"),
        ("material 9 metal _shiny 1", "'_shiny' is not a material parameter"),
        ("material 9 metal _rough", "missing a number for _rough"),
        ("rgb 0 1 2 3", "palette index 0 is outside 1..=255"),
        ("rgb 9 1 2 300", "blue 300 is outside 0..=255"),
        ("extrude 0 0 0 0 1 0 5000", "layers 5000 is outside -4096..=4096"),
    ] {
        let (out, text) = run_script(&format!("new\n{line}\n"));
        assert!(!out.status.success(), "{line}");
        assert!(text.contains(message) && text.contains("bad.ovr:2:"), "{line}: {text}");
    }
}

/// An extrude without a face, with a slanted normal, or past the world's
/// edge is refused and changes nothing.
#[test]
fn a_refused_extrude_changes_nothing() {
    for (line, message) in [
        ("extrude 0 5 0 0 1 0 1", "shows no face"),
        ("extrude 0 0 0 1 1 0 1", "is not one of ±x, ±y, ±z"),
        ("extrude 0 0 0 0 1 0 0", "extrude by 0 layers"),
        ("extrude 16777210 0 0 1 0 0 4096", "outside the world"),
    ] {
        let start = if line.starts_with("extrude 1677") { "place 16777210 0 0" } else { "place 0 0 0" };
        let (out, text) = run_script(&format!(
            "new
{start}
{line}
expect count 1
"
        ));
        assert!(!out.status.success() && text.contains(message), "{line}: {text}");
    }
}

#[test]
fn pick_takes_the_colour_of_a_voxel() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("pick.ovr");
    std::fs::write(&path, "new\ncolor 9\nplace 0 0 0\ncolor 4\npick 0 0 0\nplace 1 0 0\nexpect voxel 1 0 0 9\n")
        .unwrap();
    for cpu in [false, true] {
        replay_passes(&path, cpu, "1 passed, 0 failed");
    }
    let (out, text) = run_script("new\npick 5 5 5\n");
    assert!(!out.status.success());
    assert!(text.contains("no voxel at [5, 5, 5] to pick a colour from") && text.contains("bad.ovr:2"), "{text}");
}

#[test]
fn fill_recolours_the_connected_region_of_one_colour_in_one_step() {
    use glam::IVec3;
    use octovox::scene::{Op, Scene, Shape};
    // Box A and box B touch and share colour 3; box C has colour 3 but is
    // apart; box D touches A with colour 5.
    let boxes = [
        (IVec3::new(0, 0, 0), IVec3::new(3, 3, 3), 3u8),
        (IVec3::new(4, 0, 0), IVec3::new(5, 1, 1), 3),
        (IVec3::new(10, 0, 0), IVec3::new(11, 1, 1), 3),
        (IVec3::new(0, 4, 0), IVec3::new(1, 5, 1), 5),
    ];
    let dir = tempfile::tempdir().unwrap();
    let mut scene = Scene::default();
    for (min, max, color) in boxes {
        scene.apply_brush(&Shape::Box { min, max }, Op::Place(color)).unwrap();
    }
    octovox::io::save_scene(&dir.path().join("boxes.vox"), &scene, Default::default()).unwrap();
    let script = "load boxes.vox\ncolor 7\nfill 1 1 1\nexpect voxel 5 1 1 7\nexpect voxel 10 0 0 3\nexpect voxel 0 4 0 5\n\
                  save filled.vox\nundo\nexpect voxel 5 1 1 3\nexpect voxel 0 0 0 3\n";
    let path = dir.path().join("fill.ovr");
    std::fs::write(&path, script).unwrap();
    for cpu in [false, true] {
        replay_passes(&path, cpu, "5 passed, 0 failed");
        // Every voxel, against the boxes: A and B are 7, C and D unchanged.
        let filled = octovox::io::load_scene(&dir.path().join("filled.vox"), 0).unwrap();
        for (p, c) in filled.voxels() {
            let (_, _, original) =
                boxes.iter().copied().find(|(lo, hi, _)| p.cmpge(*lo).all() && p.cmple(*hi).all()).unwrap();
            let expected = if p.x <= 5 && original == 3 { 7 } else { original };
            assert_eq!(c, expected, "voxel {p}");
        }
    }
    let (out, text) = run_script("new\nfill 5 5 5\n");
    assert!(!out.status.success());
    assert!(text.contains("no voxel at [5, 5, 5] to fill from") && text.contains("bad.ovr:2"), "{text}");
}

#[test]
fn mirrored_edits_land_on_both_sides_in_one_step() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mirror.ovr");
    // x = 0.5 is the centre of voxel 0: voxel x maps to -x; z = 0 maps z to -z - 1.
    let script = "new\ncolor 5\nmirror x 0.5\nplace 3 0 0\nexpect voxel -3 0 0 5\nexpect count 2\nundo\nexpect count 0\n\
                  mirror z 0\nplace 1 0 5\nexpect voxel -1 0 5 5\nexpect voxel 1 0 -6 5\nexpect voxel -1 0 -6 5\n\
                  mirror off\nplace 2 2 2\nexpect voxel -2 2 2 0\nexpect count 5\n";
    std::fs::write(&path, script).unwrap();
    for cpu in [false, true] {
        replay_passes(&path, cpu, "8 passed, 0 failed");
    }
    for (line, message) in [
        ("mirror w 3", "expected x, y, z or off, found 'w'"),
        ("mirror x 0.25", "plane '0.25' must be a whole or half number"),
        ("mirror y", "missing the plane's coordinate"),
    ] {
        let (out, text) = run_script(&format!("new\n{line}\n"));
        assert!(!out.status.success(), "{line}");
        assert!(text.contains(message) && text.contains("bad.ovr:2:"), "{line}: {text}");
    }
}

#[test]
fn a_line_places_one_brush_per_step_in_one_undo_step() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("line.ovr");
    // Along x: 5 cells. The diagonal: (i, i, i). Mirrored across x = 0.5: -x.
    let script = "new\ncolor 6\nline 0 0 0 4 0 0\nexpect count 5\nexpect voxel 4 0 0 6\nundo\nexpect count 0\n\
                  line 0 0 0 3 3 3\nexpect count 4\nexpect voxel 2 2 2 6\nexpect voxel 1 1 1 6\n\
                  mirror x 0.5\nline 2 5 0 2 7 0\nexpect voxel -2 6 0 6\nexpect count 10\n";
    std::fs::write(&path, script).unwrap();
    for cpu in [false, true] {
        replay_passes(&path, cpu, "8 passed, 0 failed");
    }
}

/// Box selection: copy, paste, move, cut and delete, each checked voxel by
/// voxel against this test's own map arithmetic, with undo and redo.
#[test]
fn select_copy_paste_move_cut_and_delete_in_one_step_each() {
    use glam::IVec3;
    use octovox::scene::{Op, Scene, Shape};
    use std::collections::HashMap;
    type Voxels = HashMap<IVec3, u8>;
    let mut base: Voxels = HashMap::new();
    // Block A (colour 3, one voxel of 5, a hole at (2, 2, 1)), a voxel of 9
    // where A's hole lands after the paste, and a voxel of 7 apart.
    for x in 0..4 {
        for y in 0..3 {
            for z in 0..2 {
                base.insert(IVec3::new(x, y, z), 3);
            }
        }
    }
    base.insert(IVec3::new(1, 1, 0), 5);
    base.remove(&IVec3::new(2, 2, 1));
    base.insert(IVec3::new(12, 2, 1), 9);
    base.insert(IVec3::new(0, 0, 5), 7);
    let dir = tempfile::tempdir().unwrap();
    let mut scene = Scene::default();
    for (p, c) in &base {
        scene.apply_brush(&Shape::Voxel(*p), Op::Place(*c)).unwrap();
    }
    octovox::io::save_scene(&dir.path().join("blocks.vox"), &scene, Default::default()).unwrap();

    let inside = |p: IVec3, lo: IVec3, hi: IVec3| p.cmpge(lo).all() && p.cmple(hi).all();
    let boxed = |v: &Voxels, lo: IVec3, hi: IVec3| -> Voxels {
        v.iter().filter(|(p, _)| inside(**p, lo, hi)).map(|(p, c)| (*p, *c)).collect()
    };
    let without = |v: &Voxels, lo: IVec3, hi: IVec3| -> Voxels {
        v.iter().filter(|(p, _)| !inside(**p, lo, hi)).map(|(p, c)| (*p, *c)).collect()
    };
    let put = |v: &Voxels, block: &Voxels, by: IVec3| -> Voxels {
        let mut out = v.clone();
        out.extend(block.iter().map(|(p, c)| (*p + by, *c)));
        out
    };
    let (a_lo, a_hi) = (IVec3::ZERO, IVec3::new(3, 2, 1));
    let copied = boxed(&base, a_lo, a_hi);
    let pasted = put(&base, &copied, IVec3::new(10, 0, 0));
    let (m_lo, m_hi) = (IVec3::ZERO, IVec3::new(1, 2, 1));
    let moved = put(&without(&pasted, m_lo, m_hi), &boxed(&pasted, m_lo, m_hi), IVec3::new(0, 5, 0));
    let (c_lo, c_hi) = (IVec3::new(0, 5, 0), IVec3::new(1, 7, 1));
    let cut_block = boxed(&moved, c_lo, c_hi);
    let cut = without(&moved, c_lo, c_hi);
    let cut_pasted = put(&cut, &cut_block, IVec3::new(20, 0, 0) - c_lo);
    let deleted = without(&cut_pasted, IVec3::new(20, 0, 0), IVec3::new(20, 2, 1));
    assert!(pasted[&IVec3::new(12, 2, 1)] == 9 && deleted.len() < cut_pasted.len(), "the cases are not trivial");

    let script = format!(
        "load blocks.vox\nselect 3 2 1 0 0 0\ncopy\npaste 10 0 0\nsave pasted.vox\nundo\nexpect count {}\nredo\n\
         select 0 0 0 1 2 1\nmove 0 5 0\nsave moved.vox\nundo\nsave move_undone.vox\nredo\n\
         cut\nsave cut.vox\npaste 20 0 0\nsave cut_pasted.vox\nselect 20 0 0 20 2 1\ndelete\nsave deleted.vox\n\
         undo\nexpect count {}\nredo\nexpect count {}\n",
        base.len(),
        cut_pasted.len(),
        deleted.len()
    );
    let path = dir.path().join("select.ovr");
    std::fs::write(&path, script).unwrap();
    let read = |name: &str| -> Voxels {
        octovox::io::load_scene(&dir.path().join(name), 0).unwrap().voxels().into_iter().collect()
    };
    for cpu in [false, true] {
        replay_passes(&path, cpu, "3 passed, 0 failed");
        for (name, want) in [
            ("pasted.vox", &pasted),
            ("moved.vox", &moved),
            ("move_undone.vox", &pasted),
            ("cut.vox", &cut),
            ("cut_pasted.vox", &cut_pasted),
            ("deleted.vox", &deleted),
        ] {
            assert_eq!(&read(name), want, "{name}");
        }
        for name in ["pasted.vox", "moved.vox", "move_undone.vox", "cut.vox", "cut_pasted.vox", "deleted.vox"] {
            std::fs::remove_file(dir.path().join(name)).unwrap();
        }
    }
}

/// Lines that need a selection, a clipboard or room in the world say so
/// with file:line and change nothing.
#[test]
fn selection_lines_that_cannot_run_are_refused() {
    for (script, message) in [
        ("new\ncopy\n", "nothing is selected"),
        ("new\npaste 0 0 0\n", "nothing to paste"),
        ("new\nplace 0 0 0\nplace 1 0 0\nselect 0 0 0 1 0 0\nmove 16777215 0 0\n", "outside the world"),
        ("new\nselect 0 0 0 9000 0 0\n", "at most 4096 voxels wide"),
        ("new\nmove 1 2\n", "missing Z"),
    ] {
        let (out, text) = run_script(script);
        assert!(!out.status.success(), "{script}");
        let line = script.lines().count();
        assert!(text.contains(message) && text.contains(&format!("bad.ovr:{line}")), "{script}: {text}");
    }
}
