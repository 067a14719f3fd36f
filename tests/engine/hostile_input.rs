//! The failures found by trying to break octovox (issue "Nothing lost,
//! nothing silent"), one test each, run as a user runs the binary. Each
//! failed before its fix.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use crate::common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use glam::IVec3;
use octovox::io::atomic::{WriteOptions, write_atomically};
use octovox::scene::{Octree, Op, Shape};

fn octovox(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_octovox")).args(args).output().expect("run octovox")
}

fn text(out: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
}

/// Fails unless the command exited non-zero with `needle` in its output
/// and without a panic.
fn assert_refused(out: &Output, needle: &str) {
    let text = text(out);
    assert!(!out.status.success(), "exited 0: {text}");
    assert!(text.contains(needle), "expected '{needle}' in: {text}");
    assert!(!text.contains("panicked"), "{text}");
}

fn torus() -> PathBuf {
    common::assets().join("vox/seed/torus64.vox")
}

fn s(path: &Path) -> &str {
    path.to_str().expect("UTF-8 temp path")
}

/// A copy of torus64.vox in a fresh folder.
fn model_in(dir: &Path) -> PathBuf {
    let model = dir.join("model.vox");
    common::copy_writable(&torus(), &model);
    model
}

// ----- 1, 2: an output that is an input or an existing document --------------

#[test]
fn render_never_writes_over_its_input_or_a_document() {
    let dir = tempfile::tempdir().unwrap();
    let model = model_in(dir.path());
    let before = std::fs::read(&model).unwrap();
    let m = s(&model);
    assert_refused(&octovox(&["render", m, "-o", m, "--cpu", "--size", "8x8"]), "writes .png files");
    let png_named_vox = dir.path().join("render.png");
    common::copy_writable(&model, &png_named_vox);
    // Same file through another name: refused as an input even with the right extension.
    assert_refused(
        &octovox(&["render", s(&png_named_vox), "-o", s(&png_named_vox), "--cpu", "--size", "8x8"]),
        "is an input",
    );
    assert_eq!(std::fs::read(&model).unwrap(), before, "the model changed");
    let obj = dir.path().join("mesh.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n").unwrap();
    assert_refused(&octovox(&["render", s(&obj), "-o", s(&obj), "--cpu"]), "writes .png files");
    assert!(std::fs::read_to_string(&obj).unwrap().starts_with("v 0 0 0"));
}

#[test]
fn convert_and_import_replace_an_existing_vox_only_with_force() {
    let dir = tempfile::tempdir().unwrap();
    let model = model_in(dir.path());
    let out = dir.path().join("out.vox");
    std::fs::write(&out, b"keep me").unwrap();
    assert_refused(&octovox(&["convert", s(&model), s(&out)]), "already exists");
    assert_eq!(std::fs::read(&out).unwrap(), b"keep me");
    assert_refused(&octovox(&["convert", s(&model), s(&model)]), "is an input");
    let done = octovox(&["convert", s(&model), s(&out), "--force"]);
    assert!(done.status.success(), "{}", text(&done));
    assert!(std::fs::read(&out).unwrap().starts_with(b"VOX "));
    let mesh = common::assets().join("meshes/bunny.obj");
    if mesh.exists() {
        assert_refused(&octovox(&["import", s(&mesh), "-o", s(&out), "--size", "16"]), "already exists");
    }
}

#[test]
fn record_refuses_the_model_and_the_script_it_plays() {
    let dir = tempfile::tempdir().unwrap();
    let model = model_in(dir.path());
    let before = std::fs::read(&model).unwrap();
    // Refused before any window opens, so no display is needed.
    assert_refused(&octovox(&[s(&model), "--record", s(&model)]), "is an input");
    assert_eq!(std::fs::read(&model).unwrap(), before, "--record truncated the model");
    let script = dir.path().join("s.ovr");
    std::fs::write(&script, "demo\n").unwrap();
    assert_refused(&octovox(&["--replay", s(&script), "--record", s(&script)]), "is an input");
    assert_eq!(std::fs::read_to_string(&script).unwrap(), "demo\n");
    let other = dir.path().join("other.ovr");
    std::fs::write(&other, "new\n").unwrap();
    assert_refused(&octovox(&["--record", s(&other)]), "already exists");
}

#[test]
fn replay_save_and_render_follow_the_same_rule() {
    let dir = tempfile::tempdir().unwrap();
    let model = model_in(dir.path());
    let before = std::fs::read(&model).unwrap();
    let script = dir.path().join("overwrite.ovr");
    std::fs::write(&script, "load model.vox\nsave model.vox\n").unwrap();
    assert_refused(&octovox(&["replay", "--cpu", s(&script)]), "is an input");
    assert_eq!(std::fs::read(&model).unwrap(), before);
    // A file the run wrote itself may be written again.
    std::fs::write(
        &script,
        "new\nplace 0 0 0\nsave again.vox\nplace 1 0 0\nsave again.vox\nrender r.png\nrender r.png\n",
    )
    .unwrap();
    let out = octovox(&["replay", "--cpu", s(&script)]);
    assert!(out.status.success(), "{}", text(&out));
    // A second run finds again.vox from the first: refused without --force.
    assert_refused(&octovox(&["replay", "--cpu", s(&script)]), "already exists");
    let out = octovox(&["replay", "--cpu", "--force", s(&script)]);
    assert!(out.status.success(), "{}", text(&out));
}

// ----- 3: where a save writes ------------------------------------------------------

fn write_bytes(path: &Path, bytes: &[u8], options: WriteOptions) -> std::io::Result<()> {
    write_atomically(path, options, |file| std::io::Write::write_all(file, bytes))
}

#[cfg(unix)]
#[test]
fn saves_follow_links_and_refuse_devices_fifos_and_read_only_files() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("real.vox");
    std::fs::write(&target, b"old").unwrap();
    let link = dir.path().join("link.vox");
    std::os::unix::fs::symlink("real.vox", &link).unwrap();
    write_bytes(&link, b"new", WriteOptions::default()).unwrap();
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link became a file");
    assert_eq!(std::fs::read(&target).unwrap(), b"new", "the link's target was not updated");

    let err = write_bytes(Path::new("/dev/null"), b"x", WriteOptions::default()).unwrap_err();
    assert!(err.to_string().contains("not a regular file"), "{err}");
    let fifo = dir.path().join("pipe.vox");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let err = write_bytes(&fifo, b"x", WriteOptions::default()).unwrap_err();
    assert!(err.to_string().contains("not a regular file"), "{err}");
    assert!(!std::fs::symlink_metadata(&fifo).unwrap().is_file(), "the FIFO was replaced");

    let locked = dir.path().join("locked.vox");
    std::fs::write(&locked, b"mine").unwrap();
    std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o444)).unwrap();
    let err = write_bytes(&locked, b"x", WriteOptions::default()).unwrap_err();
    assert!(err.to_string().contains("read-only"), "{err}");
    assert_eq!(std::fs::read(&locked).unwrap(), b"mine");
    write_bytes(&locked, b"forced", WriteOptions::forced(true)).unwrap();
    assert_eq!(std::fs::read(&locked).unwrap(), b"forced");
    assert_eq!(std::fs::metadata(&locked).unwrap().permissions().mode() & 0o777, 0o444, "still read-only");
    // The CLI: refused, and --force overwrites.
    let png = dir.path().join("ro.png");
    std::fs::write(&png, b"mine").unwrap();
    std::fs::set_permissions(&png, std::fs::Permissions::from_mode(0o444)).unwrap();
    assert_refused(&octovox(&["render", "--cpu", "--size", "8x8", "-o", s(&png)]), "read-only");
    assert_eq!(std::fs::read(&png).unwrap(), b"mine");
    let out = octovox(&["render", "--cpu", "--size", "8x8", "-o", s(&png), "--force"]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(octovox::io::png::load_png(&png).is_ok());
}

#[test]
fn a_save_cleans_up_what_a_killed_save_of_the_same_file_left() {
    let dir = tempfile::tempdir().unwrap();
    let stale = dir.path().join(".scene.vox.octovox-save-AbC123.tmp");
    let unrelated = dir.path().join(".other.vox.octovox-save-AbC123.tmp");
    std::fs::write(&stale, b"half a file").unwrap();
    std::fs::write(&unrelated, b"another document's").unwrap();
    write_bytes(&dir.path().join("scene.vox"), b"VOX ", WriteOptions::default()).unwrap();
    assert!(!stale.exists(), "the stale temporary file is still there");
    assert!(unrelated.exists(), "another document's temporary file was removed");
}

// ----- 4, 5, 6: memory ------------------------------------------------------------------

#[test]
fn a_scene_too_large_for_a_vox_file_is_an_error_not_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("big.ovr");
    // 4/3·π·300³ ≈ 113 M voxels: more than a .vox file octovox reads back.
    std::fs::write(&script, "new\nbrush sphere 300\nplace 0 0 0\nsave big.vox\n").unwrap();
    assert_refused(&octovox(&["replay", "--cpu", s(&script)]), "a .vox file octovox can read back holds at most");
    assert!(!dir.path().join("big.vox").exists());
}

#[test]
fn imports_are_checked_against_the_budget_and_what_can_be_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let cube = dir.path().join("cube.obj");
    let faces =
        "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";
    let vertices = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n";
    std::fs::write(&cube, format!("{vertices}{faces}")).unwrap();
    let out = dir.path().join("cube.vox");
    assert_refused(
        &octovox(&["--memory-budget", "256M", "import", s(&cube), "-o", s(&out), "--size", "4096"]),
        "--memory-budget raises it",
    );
    // 416³ = 72 M voxels fits the budget but not a file octovox reads back.
    assert_refused(&octovox(&["import", s(&cube), "-o", s(&out), "--size", "416"]), "can read back");
    assert!(!out.exists(), "a file octovox cannot read was written");
}

#[test]
fn loads_brushes_and_renders_are_checked_against_the_budget() {
    let torus = torus();
    assert_refused(&octovox(&["--memory-budget", "64K", "info", s(&torus)]), "over the 64.0 KiB budget");
    assert_refused(
        &octovox(&["render", "--cpu", "--size", "16384x16384", "-o", "/tmp/octovox-never.png"]),
        "a 16384x16384 render would need about",
    );
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("sphere.ovr");
    std::fs::write(&script, "new\nplace 0 0 0\nbrush sphere 4096\nplace 0 0 0\n").unwrap();
    assert_refused(&octovox(&["--memory-budget", "1G", "replay", "--cpu", s(&script)]), "over the 1.0 GiB budget");
    // The refused edit changed nothing.
    // Over the default budget too; the refused edit changed nothing.
    let mut tree = Octree::default();
    tree.apply_brush(&Shape::Voxel(IVec3::ZERO), Op::Place(1)).unwrap();
    let before = tree.voxels();
    let big = Shape::Sphere { center: IVec3::ZERO, radius: 4096 };
    let err = tree.apply_brush(&big, Op::Place(2)).unwrap_err();
    assert!(err.to_string().contains("budget"), "{err}");
    assert_eq!(tree.voxels(), before);
    assert_eq!((tree.origin(), tree.depth()), (IVec3::ZERO, 2));
}

#[test]
fn a_small_obj_of_many_stacked_planes_is_checked_against_the_budget() {
    // 3000 planes over the whole footprint: 3000 crossings in each of the
    // 256² columns, about 1.5 GB for a 200 KB file.
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::new();
    for k in 0..3000 {
        let y = f64::from(k) / 3000.0;
        text += &format!("v 0 {y} 0\nv 1 {y} 0\nv 0 {y} 1\nf -3 -2 -1\n");
    }
    let planes = dir.path().join("planes.obj");
    std::fs::write(&planes, text).unwrap();
    let out = dir.path().join("planes.vox");
    assert_refused(&octovox(&["--memory-budget", "1G", "import", s(&planes), "-o", s(&out)]), "voxelizing");
}

#[cfg(unix)]
#[test]
fn devices_are_refused_as_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("z.vox");
    assert_refused(&octovox(&["import", "/dev/zero", "-o", s(&out)]), "not a regular file");
    assert_refused(&octovox(&["replay", "--cpu", "/dev/zero"]), "not a regular file");
    assert_refused(&octovox(&["info", "/dev/zero"]), "not a regular file");
}

// ----- 7, 8: GPU limits: a clear error or a real image, never a blank one -----------

/// Fraction of pixels that are not pure black.
fn lit_fraction(path: &Path) -> f64 {
    let image = octovox::io::png::load_png(path).unwrap();
    image.pixels().filter(|p| p.0[..3] != [0, 0, 0]).count() as f64 / f64::from(image.width() * image.height())
}

#[test]
fn large_gpu_renders_draw_the_scene_or_fail() {
    let dir = tempfile::tempdir().unwrap();
    // 2900² pixels of hit records were 134 MB, over lavapipe's 128 MiB
    // binding limit: the image came out black with exit 0.
    let big = dir.path().join("big.png");
    let out = octovox(&["render", s(&torus()), "--size", "2900x2900", "-o", s(&big)]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(lit_fraction(&big) > 0.99, "the render is black");
    // Past the default 8192 texture limit wgpu panicked.
    let wide = dir.path().join("wide.png");
    let out = octovox(&["render", s(&torus()), "--size", "8193x48", "-o", s(&wide)]);
    if out.status.success() {
        assert!(lit_fraction(&wide) > 0.99, "the render is black");
    } else {
        assert_refused(&out, "limit for an image");
    }
    // A dense grid over the binding limit fails the command.
    let script = dir.path().join("wide.ovr");
    std::fs::write(&script, "new\nplace 0 0 0\nplace 600 600 600\nsave wide.vox\n").unwrap();
    let made = octovox(&["replay", "--cpu", s(&script)]);
    assert!(made.status.success(), "{}", text(&made));
    let grid = dir.path().join("grid.png");
    let out = octovox(&["render", s(&dir.path().join("wide.vox")), "--mode", "grid", "-o", s(&grid)]);
    assert_refused(&out, "the dense grid needs a");
    assert!(!grid.exists());
}

// ----- 9, 10: a ray past 4096 cells, a refused edit ----------------------------------

/// A row of 2000 voxels one voxel beside a ray along +x, and a wall 4010
/// voxels away: the traversal passes more than 4096 cells before the wall.
fn comb() -> Octree {
    let mut tree = Octree::default();
    for i in 0..2000 {
        tree.apply_brush(&Shape::Voxel(IVec3::new(2 * i, 1, 0)), Op::Place(5)).unwrap();
    }
    tree.apply_brush(&Shape::Box { min: IVec3::new(4010, -8, -8), max: IVec3::new(4010, 8, 8) }, Op::Place(9)).unwrap();
    tree
}

/// The comb: a ray that passes more than 4096 cells (the old fixed bound,
/// at which it returned sky and the pick said "nothing") reaches the wall.
#[test]
fn the_comb_ray_reaches_the_wall_in_the_pick() {
    let tree = comb();
    let camera = octovox::camera::Camera {
        eye: glam::DVec3::new(-2.0, 0.5, 0.5),
        target: glam::DVec3::new(100.0, 0.5, 0.5),
        fov_y_deg: 1.0,
        ortho: None,
    };
    let depth = tree.depth();
    let scene = octovox::scene::Scene::new(Default::default(), tree);
    let picked = octovox::trace::pick::pick(&scene, &camera, (1, 1), 0, 0).unwrap().expect("the wall");
    assert_eq!(picked.voxel.x, 4010);
    // The pick's own ray, traced alone for its count.
    let (origin, dir) = camera.basis(1, 1, scene.origin()).ray(0, 0);
    let traced = octovox::trace::instanced::Traced::of(&scene);
    let hit = traced.trace(&octovox::trace::Ray::new(origin, dir), octovox::trace::Footprint::EXACT);
    assert_eq!(hit.voxel.x + scene.origin().x, 4010);
    println!("the comb ray took {} iterations", hit.iterations);
    assert!(hit.iterations > 4096, "{} iterations", hit.iterations);
    assert!(hit.iterations < octovox::trace::iteration_bound(depth));
    // Were a ray ever to give up, it is drawn magenta, not as sky.
    let gave_up = octovox::trace::Hit { gave_up: true, iterations: 7, ..Default::default() };
    let color = octovox::trace::render::shade(&gave_up, glam::Vec3::X, &Default::default(), Default::default(), false);
    assert_eq!(color, [255, 0, 255, 255]);
}

#[test]
fn the_comb_ray_reaches_the_wall_in_cpu_and_gpu_renders() {
    let dir = tempfile::tempdir().unwrap();
    let mut script = String::from("new\n");
    for i in 0..2000 {
        script += &format!("place {} 1 0\n", 2 * i);
    }
    script += "color 9\nbrush box 1 17 17\nplace 4010 0 0\nsave comb.vox\n";
    let path = dir.path().join("comb.ovr");
    std::fs::write(&path, script).unwrap();
    let made = octovox(&["replay", "--cpu", s(&path)]);
    assert!(made.status.success(), "{}", text(&made));
    let comb = dir.path().join("comb.vox");
    let camera = ["--camera", "-2,0.5,0.5:100,0.5,0.5", "--fov", "1", "--size", "3x3", "--no-shadows"];
    let center = |cpu: bool| {
        let png = dir.path().join(if cpu { "cpu.png" } else { "gpu.png" });
        let mut args = vec!["render", s(&comb), "-o", s(&png)];
        args.extend(camera);
        if cpu {
            args.push("--cpu");
        }
        let out = octovox(&args);
        assert!(out.status.success() && !text(&out).contains("iterations"), "{}", text(&out));
        octovox::io::png::load_png(&png).unwrap().get_pixel(1, 1).0
    };
    let (cpu, gpu) = (center(true), center(false));
    assert_eq!(cpu, gpu, "CPU and GPU disagree on the comb");
    let sky = octovox::trace::render::shade(
        &Default::default(),
        glam::Vec3::X,
        &Default::default(),
        Default::default(),
        false,
    );
    assert!(cpu != sky && cpu != [255, 0, 255, 255], "the centre pixel is {cpu:?}, not the wall");
}

#[test]
fn a_refused_edit_leaves_the_scene_exactly_as_it_was() {
    let mut tree = Octree::default();
    tree.apply_brush(&Shape::Voxel(IVec3::ZERO), Op::Place(1)).unwrap();
    let before = (tree.voxels(), tree.origin(), tree.depth(), tree.node_count());
    let err = tree.apply_brush(&Shape::Voxel(IVec3::new(1 << 20, 0, 0)), Op::Place(1)).unwrap_err();
    assert!(err.to_string().contains("wider than 2^20"), "{err}");
    assert_eq!((tree.voxels(), tree.origin(), tree.depth(), tree.node_count()), before, "the refusal changed the tree");
    tree.apply_brush(&Shape::Voxel(IVec3::new(-2, 0, 0)), Op::Place(1)).unwrap();
    assert_eq!(tree.solid_voxels(), 2);
}

#[test]
fn any_edit_that_fits_the_2_pow_20_world_is_accepted() {
    // Growing toward -4 first leaves the root's alignment short on +x; the
    // root moves instead of refusing an edit the world has room for.
    let mut tree = Octree::default();
    tree.apply_brush(&Shape::Voxel(IVec3::new(-1, 0, 0)), Op::Place(1)).unwrap();
    tree.apply_brush(&Shape::Voxel(IVec3::new(0, 0, 0)), Op::Place(2)).unwrap();
    let far = IVec3::new((1 << 20) - 2, 0, 0);
    tree.apply_brush(&Shape::Voxel(far), Op::Place(3)).unwrap();
    assert_eq!(tree.get(far), 3);
    assert_eq!(tree.get(IVec3::new(-1, 0, 0)), 1);
    assert_eq!(tree.solid_voxels(), 3);
    tree.check_invariants().unwrap();
    assert!(tree.apply_brush(&Shape::Voxel(IVec3::new(-2, 0, 0)), Op::Place(1)).is_err());
}

// ----- 11, 14: field of view, negative numbers -----------------------------------------

#[test]
fn fields_of_view_outside_the_range_are_refused_and_narrow_ones_frame_the_model() {
    for fov in ["nan", "inf", "180", "360", "0", "-5"] {
        let out = octovox(&["render", "--cpu", "--fov", fov, "-o", "/tmp/octovox-fov.png"]);
        assert_refused(&out, "1..=179");
    }
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("narrow.png");
    let out = octovox(&["render", "--cpu", "--fov", "2", "--size", "48x32", "-o", s(&png)]);
    assert!(out.status.success(), "{}", text(&out));
    let image = octovox::io::png::load_png(&png).unwrap();
    let sky = image.get_pixel(0, 0).0;
    let model = image.pixels().filter(|p| p.0 != sky).count();
    // Framed: the demo scene fills much of the view, but not all of it.
    assert!(model > 48 * 32 / 8 && model < 48 * 32, "{model} pixels of the model");
}

#[test]
fn negative_numbers_are_accepted_in_numeric_options() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("neg.png");
    let out = octovox(&["render", "--cpu", "--size", "16x16", "--camera", "-5,3,4:0,0,0", "-o", s(&png)]);
    assert!(out.status.success(), "{}", text(&out));
    let out = octovox(&["import", "x.obj", "-o", "x.vox", "--size", "-5"]);
    let t = text(&out);
    assert!(!out.status.success() && !t.contains("unexpected argument"), "{t}");
}

// ----- 12: quoting in scripts ------------------------------------------------------------

#[test]
fn a_quoted_path_with_a_hash_saves_where_it_says() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("hash.ovr");
    std::fs::write(&script, "\u{feff}new\nplace 0 0 0\nsave \"has#hash and space.vox\" # saved\n").unwrap();
    let out = octovox(&["replay", "--cpu", s(&script)]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(dir.path().join("has#hash and space.vox").exists());
    assert!(!dir.path().join("has").exists());
}

// ----- 13: files the loader accepts with a warning -------------------------------------

/// A .vox of `models` one-voxel models and no scene graph, then `tail`.
fn vox_without_scene_graph(models: usize, extra_voxel_bytes: usize, tail: &[u8]) -> Vec<u8> {
    let mut children = Vec::new();
    for _ in 0..models {
        children.extend(b"SIZE");
        children.extend(12u32.to_le_bytes());
        children.extend(0u32.to_le_bytes());
        children.extend([1u32, 1, 1].iter().flat_map(|v| v.to_le_bytes()));
        children.extend(b"XYZI");
        children.extend(u32::try_from(8 + extra_voxel_bytes).unwrap().to_le_bytes());
        children.extend(0u32.to_le_bytes());
        children.extend(1u32.to_le_bytes());
        children.extend([0, 0, 0, 1]);
        children.extend(std::iter::repeat_n(7u8, extra_voxel_bytes));
    }
    let mut bytes = b"VOX ".to_vec();
    bytes.extend(150u32.to_le_bytes());
    bytes.extend(b"MAIN");
    bytes.extend(0u32.to_le_bytes());
    bytes.extend(u32::try_from(children.len()).unwrap().to_le_bytes());
    bytes.extend(children);
    bytes.extend(tail);
    bytes
}

#[test]
fn ignored_bytes_are_reported_and_models_counted() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.vox");
    std::fs::write(&path, vox_without_scene_graph(3000, 0, b"trailing junk")).unwrap();
    let out = octovox(&["info", "--json", s(&path)]);
    assert!(out.status.success(), "{}", text(&out));
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(info["stored_models"], 3000);
    assert_eq!(info["models"], 1);
    let warnings = info["warnings"].to_string();
    assert!(warnings.contains("13 bytes after the MAIN chunk"), "{warnings}");

    std::fs::write(&path, vox_without_scene_graph(1, 8, b"")).unwrap();
    let out = octovox(&["info", s(&path)]);
    let t = text(&out);
    assert!(out.status.success() && t.contains("holds 8 bytes past its 1 voxels"), "{t}");
}

// ----- 17: .obj errors ----------------------------------------------------------------

#[test]
fn obj_errors_name_the_line_and_the_cause() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.vox");
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "# a mesh\nv 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert_refused(
        &octovox(&["import", s(&bad), "-o", s(&out)]),
        "bad.obj:3: vertex coordinate 'zero' is not a number",
    );
    let huge = dir.path().join("huge.obj");
    std::fs::write(&huge, "v -3e38 0 0\nv 3e38 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 2 4\nf 2 3 4\n").unwrap();
    assert_refused(&octovox(&["import", s(&huge), "-o", s(&out)]), "huge.obj:1: vertex coordinate -3e38 is so large");
}

// ----- 18, 19, 20: files and pipes ------------------------------------------------------

#[cfg(unix)]
#[test]
fn images_and_scenes_are_written_alike() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("a.png");
    let vox = dir.path().join("a.vox");
    let cmd = format!(
        "umask 022 && '{bin}' render --cpu --size 8x8 -o '{png}' && '{bin}' convert '{torus}' '{vox}'",
        bin = env!("CARGO_BIN_EXE_octovox"),
        png = s(&png),
        vox = s(&vox),
        torus = s(&torus())
    );
    assert!(Command::new("sh").args(["-c", &cmd]).status().unwrap().success());
    for file in [&png, &vox] {
        assert_eq!(std::fs::metadata(file).unwrap().permissions().mode() & 0o777, 0o644, "{}", file.display());
    }
    let deep = dir.path().join("a/b/c/x.png");
    assert_refused(&octovox(&["render", "--cpu", "--size", "8x8", "-o", s(&deep)]), "does not exist");
    let deep_vox = dir.path().join("a/b/c/x.vox");
    assert_refused(&octovox(&["convert", s(&torus()), s(&deep_vox)]), "does not exist");
    assert_refused(&octovox(&["render", "--cpu", "-o", s(&dir.path().join("x.jpg"))]), "names a .jpg file");
}

#[test]
fn convert_is_deterministic() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::assets().join("vox/format/metal-material.vox");
    let (a, b) = (dir.path().join("a.vox"), dir.path().join("b.vox"));
    for out in [&a, &b] {
        let done = octovox(&["convert", s(&input), s(out)]);
        assert!(done.status.success(), "{}", text(&done));
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn a_closed_pipe_is_a_normal_end() {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["info", s(&torus())])
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// Issue 24, item 11: an extrude of a million faces by 4096 layers (within
/// the documented limits) had no estimate and aborted at 4 GB after 25 s;
/// the whole step is now estimated before any of it is applied.
#[test]
fn an_extrude_is_estimated_against_the_budget_before_it_is_built() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("extrude.ovr");
    std::fs::write(&script, "new\nbrush box 1024 1 1024\nplace 0 0 0\nextrude 0 0 0 0 1 0 4096\n").unwrap();
    let out = octovox(&["--memory-budget", "1G", "replay", "--cpu", s(&script)]);
    assert_refused(&out, "a step of 1048576 edits would need about");
    assert_refused(&out, "over the 1.0 GiB budget");
}

/// Issue 24, item 12: a line across the whole coordinate range built its
/// 33 million cells (4.1 GB) before the world-width check refused it. Run
/// under a 1.5 GiB address-space limit, the old code aborted.
#[test]
fn a_line_wider_than_the_world_is_refused_before_its_cells_are_built() {
    let dir = tempfile::tempdir().unwrap();
    let script = dir.path().join("line.ovr");
    std::fs::write(&script, "new\nline -16777215 0 0 16777215 0 0\n").unwrap();
    let out = Command::new("prlimit")
        .args(["--as=1610612736", "--", env!("CARGO_BIN_EXE_octovox"), "replay", "--cpu", s(&script)])
        .output()
        .expect("prlimit (util-linux) runs octovox");
    assert_refused(&out, "would make the world wider than 2^20 voxels");
    // Within the world but over the budget: refused by the estimate, with nothing built.
    std::fs::write(&script, "new\nbrush box 4096 4096 1\nline 0 0 0 0 0 1000000\n").unwrap();
    assert_refused(&octovox(&["--memory-budget", "1G", "replay", "--cpu", s(&script)]), "a line of 1000001 brushes");
}

/// A closed cube of side `side` with its min corner at (`at`, 0, 0), as .obj text.
fn cube_obj(at: f32, side: f32) -> String {
    let mut text = String::new();
    for i in 0..8 {
        let corner = |bit: i32| if i & bit != 0 { side } else { 0.0 };
        text += &format!("v {:e} {:e} {:e}\n", at + corner(1), corner(2), corner(4));
    }
    // Six faces as quads, wound outward.
    for face in ["1 3 4 2", "5 6 8 7", "1 2 6 5", "3 7 8 4", "1 5 7 3", "2 4 8 6"] {
        text += &format!("f {face}\n");
    }
    text
}

/// Issue 24, item 18: a closed mesh too small, or too far from the origin
/// for its size, was "encloses no voxel centre (is it closed?)"; the
/// message now says what is wrong with its coordinates.
#[test]
fn meshes_too_small_or_too_far_to_voxelize_say_so() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ovx");
    for (at, side, why) in [(0.0, 1e-38, "too small"), (1e30, 1.0, "too far from the origin"), (0.0, 1.0, "")] {
        let mesh = dir.path().join("cube.obj");
        std::fs::write(&mesh, cube_obj(at, side)).unwrap();
        let run = octovox(&["import", s(&mesh), "-o", s(&out), "--size", "16", "--force"]);
        if why.is_empty() {
            assert!(run.status.success(), "a unit cube imports: {}", text(&run));
        } else {
            assert_refused(&run, why);
            assert!(!text(&run).contains("is it closed"), "{}", text(&run));
        }
    }
}

/// `--oidn` needs samples, cannot be mixed with `--denoise`, and a build
/// without Open Image Denoise says how to get one; none writes an image.
#[test]
fn open_image_denoise_is_refused_clearly_where_it_cannot_run() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("o.png");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "--cpu", "--size", "8x8", "-o", s(&png)];
        args.extend_from_slice(extra);
        octovox(&args)
    };
    assert_refused(&render(&["--oidn"]), "give --spp N");
    assert_refused(&render(&["--spp", "1", "--oidn", "--denoise"]), "cannot be used with");
    if !octovox::trace::oidn::AVAILABLE {
        assert_refused(&render(&["--spp", "1", "--oidn"]), "--features oidn");
    }
    assert!(!png.exists(), "a refused render wrote {}", png.display());
}

/// `--seed` needs samples, and a seed whose sequence would wrap onto seed
/// 0's is refused; neither writes an image.
#[test]
fn a_seed_without_samples_or_past_the_last_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("s.png");
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "--cpu", "--size", "8x8", "-o", s(&png)];
        args.extend_from_slice(extra);
        octovox(&args)
    };
    assert_refused(&render(&["--seed", "2"]), "give --spp N");
    assert_refused(&render(&["--spp", "1", "--seed", "4096"]), "4096");
    assert!(!png.exists(), "a refused render wrote {}", png.display());
}

/// Issue 47, item 7: the CLI printed "error: XDG_RUNTIME_DIR is invalid…"
/// twice and then succeeded (Mesa's device-select layer probing Wayland).
/// A command run without XDG_RUNTIME_DIR now says nothing of it.
#[test]
fn a_render_without_a_runtime_dir_prints_no_driver_noise() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.png");
    let run = Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(["render", s(&torus()), "-o", s(&out), "--size", "64x36"])
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .output()
        .unwrap();
    let text = text(&run);
    assert!(run.status.success(), "{text}");
    assert!(!text.contains("XDG_RUNTIME_DIR"), "{text}");
}
