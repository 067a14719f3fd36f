//! Helpers of the window tests: an Xvfb display of their own, xdotool, the
//! app's stdout, CPU-chosen click targets, screenshots.

use std::collections::HashSet;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

use glam::IVec3;
use octovox::camera::Camera;
use octovox::scene::Octree;
use octovox::trace::{Ray, svo};

pub const WIDTH: u32 = 800;
pub const HEIGHT: u32 = 600;
/// The left panel is 236 points wide and the menu bar about 25 high; clicks
/// stay clear of both.
pub const FREE_X: u32 = 300;
pub const FREE_Y: u32 = 60;
/// A scene of objects has the Outliner over the window's right 280 points
/// (`src/app/outliner.rs`).
pub const OUTLINER_X: u32 = WIDTH - 280;

/// Kills a child process when dropped (also when the test panics).
pub struct KillOnDrop(pub Child, pub &'static str);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        if let Ok(None) = self.0.try_wait() {
            let _ = self.0.kill();
            let _ = self.0.wait();
            eprintln!("(stopped {})", self.1);
        }
    }
}

pub fn require_tool(name: &str) {
    let found =
        std::env::var_os("PATH").is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(name).is_file()));
    assert!(
        found,
        "`{name}` is not installed; the window test needs Xvfb, xdotool, xwd and ImageMagick: \
         apt-get install -y mesa-vulkan-drivers xvfb xdotool x11-apps imagemagick"
    );
}

/// What every window test needs: Xvfb for a display, xdotool for input.
pub fn require_window_tools() {
    for tool in ["Xvfb", "xdotool"] {
        require_tool(tool);
    }
}

/// Waits for the app to exit by itself; `what` says what should end it.
pub fn wait_for_exit(app: &mut KillOnDrop, timeout: Duration, what: &str) -> std::process::ExitStatus {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(status) = app.0.try_wait().expect("wait for octovox") {
            return status;
        }
        assert!(Instant::now() < deadline, "octovox did not exit on {what}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Starts Xvfb on a display number it finds free itself (`-displayfd`:
/// the server picks the number and writes it once it accepts connections),
/// so tests that run side by side never share a server.
pub fn start_xvfb() -> (KillOnDrop, String) {
    // -noreset: by default the server resets when its last client leaves,
    // and the app's connection right after the readiness probe can fail.
    let mut child = Command::new("Xvfb")
        .args(["-displayfd", "1", "-screen", "0", "1600x1000x24", "-nolisten", "tcp", "-noreset"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start Xvfb");
    let stdout = child.stdout.take().expect("stdout is piped");
    let guard = KillOnDrop(child, "Xvfb");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = BufReader::new(stdout).read_line(&mut line);
        let _ = tx.send(line);
    });
    let line = rx.recv_timeout(Duration::from_secs(30)).expect("Xvfb named no display within 30 s");
    let number: u32 = line.trim().parse().unwrap_or_else(|_| panic!("Xvfb wrote {line:?}, not a display number"));
    (guard, format!(":{number}"))
}

pub fn xdotool(display: &str, args: &[&str]) -> String {
    let out = Command::new("xdotool").args(args).env("DISPLAY", display).output().expect("cannot run xdotool");
    assert!(out.status.success(), "xdotool {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

/// Polls for the app's window (not `xdotool search --sync`, which waits
/// forever if the app died), failing with the app's stderr if it exited.
pub fn find_window(display: &str, app: &mut KillOnDrop, stderr_path: &Path) -> String {
    let deadline = Instant::now() + Duration::from_secs(90);
    loop {
        if let Ok(Some(status)) = app.0.try_wait() {
            let stderr = std::fs::read_to_string(stderr_path).unwrap_or_default();
            panic!("octovox exited ({status}) before opening its window; stderr:\n{stderr}");
        }
        let out = Command::new("xdotool").args(["search", "--name", "octovox"]).env("DISPLAY", display).output();
        if let Some(id) =
            out.ok().and_then(|o| String::from_utf8(o.stdout).ok()).and_then(|s| s.lines().next().map(str::to_string))
        {
            return id;
        }
        assert!(Instant::now() < deadline, "no octovox window within 90 s");
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The app's stdout, line by line, with a record of everything seen.
pub struct Lines {
    pub rx: Receiver<String>,
    pub seen: Vec<String>,
}

impl Lines {
    pub fn new(child: &mut Child) -> Lines {
        let stdout = child.stdout.take().expect("stdout is piped");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                eprintln!("app: {line}");
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Lines { rx, seen: Vec::new() }
    }

    /// Waits for a line starting with `prefix`; returns it.
    pub fn wait_for(&mut self, prefix: &str, timeout: Duration) -> String {
        self.try_wait_for(prefix, timeout)
            .unwrap_or_else(|| panic!("no `{prefix}` line from the app within {timeout:?}; saw {:?}", self.seen))
    }

    /// Waits for a line starting with `prefix`, or `None` after `timeout`.
    pub fn try_wait_for(&mut self, prefix: &str, timeout: Duration) -> Option<String> {
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let line = self.rx.recv_timeout(left).ok()?;
            self.seen.push(line.clone());
            if line.starts_with(prefix) {
                return Some(line);
            }
        }
    }
}

/// A pixel clear of the panels whose 5×5 neighbourhood hits the same voxel
/// through the same face, so a click there cannot land on a neighbour.
pub fn stable_pixel(tree: &Octree, camera: &Camera, accept: impl Fn(IVec3, IVec3) -> bool) -> (u32, u32, IVec3, IVec3) {
    stable_pixel_left_of(WIDTH, tree, camera, accept)
}

/// [`stable_pixel`] left of window column `right` (a panel there).
pub fn stable_pixel_left_of(
    right: u32,
    tree: &Octree,
    camera: &Camera,
    accept: impl Fn(IVec3, IVec3) -> bool,
) -> (u32, u32, IVec3, IVec3) {
    let basis = camera.basis(WIDTH, HEIGHT, tree.origin());
    let hit_at = |x: u32, y: u32| {
        let (o, d) = basis.ray(x, y);
        svo::trace(tree, &Ray::new(o, d))
    };
    let (cx, cy) = ((FREE_X + right) / 2, (FREE_Y + HEIGHT) / 2);
    let mut candidates: Vec<(u32, u32)> = (FREE_Y + 4..HEIGHT - 4)
        .step_by(3)
        .flat_map(|y| (FREE_X + 4..right - 4).step_by(3).map(move |x| (x, y)))
        .collect();
    candidates.sort_by_key(|&(x, y)| (x as i64 - cx as i64).pow(2) + (y as i64 - cy as i64).pow(2));
    for (x, y) in candidates {
        let hit = hit_at(x, y);
        if !hit.is_hit() || hit.normal == IVec3::ZERO || !accept(hit.voxel + tree.origin(), hit.normal) {
            continue;
        }
        let stable = (-2..=2).all(|dy: i32| {
            (-2..=2).all(|dx: i32| {
                let h = hit_at(x.wrapping_add_signed(dx), y.wrapping_add_signed(dy));
                h.voxel == hit.voxel && h.normal == hit.normal
            })
        });
        if stable {
            return (x, y, hit.voxel + tree.origin(), hit.normal);
        }
    }
    panic!("no pixel of the view hits a voxel face steadily");
}

/// A pixel near `from` whose ray (steadily) hits a voxel other than `voxel`
/// through the same face layer (same normal, same depth along it).
pub fn same_layer_pixel(tree: &Octree, camera: &Camera, from: (u32, u32), voxel: IVec3, normal: IVec3) -> (u32, u32) {
    let basis = camera.basis(WIDTH, HEIGHT, tree.origin());
    let hit_at = |x: u32, y: u32| {
        let (o, d) = basis.ray(x, y);
        let hit = svo::trace(tree, &Ray::new(o, d));
        (hit.voxel + tree.origin(), hit.normal, hit.is_hit())
    };
    let good = |x: u32, y: u32| {
        let (v, n, solid) = hit_at(x, y);
        solid && n == normal && v.dot(normal) == voxel.dot(normal) && v != voxel
    };
    for distance in 4..80u32 {
        for (dx, dy) in [(1i64, 0i64), (-1, 0), (0, 1), (0, -1)] {
            let x = from.0 as i64 + dx * i64::from(distance);
            let y = from.1 as i64 + dy * i64::from(distance);
            if x < i64::from(FREE_X) + 3
                || y < i64::from(FREE_Y) + 3
                || x > i64::from(WIDTH) - 4
                || y > i64::from(HEIGHT) - 4
            {
                continue;
            }
            let (x, y) = (x as u32, y as u32);
            if (x - 2..=x + 2).all(|px| (y - 2..=y + 2).all(|py| good(px, py))) {
                return (x, y);
            }
        }
    }
    panic!("no pixel near {from:?} hits the same face layer as {voxel}");
}

pub fn voxel_set(path: &Path) -> HashSet<IVec3> {
    let scene = octovox::io::load_scene(path, 0).expect("the saved file loads");
    scene.voxels().into_iter().map(|(p, _)| p).collect()
}

/// Mean and variance of the grey level of a rectangle of an image.
pub fn grey_stats(image: &image::RgbImage, x0: u32, y0: u32, x1: u32, y1: u32) -> (f64, f64) {
    let values: Vec<f64> = (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .map(|(x, y)| {
            let p = image.get_pixel(x, y);
            (f64::from(p[0]) + f64::from(p[1]) + f64::from(p[2])) / 3.0
        })
        .collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64;
    (mean, variance)
}

pub fn screenshot_x(display: &str, out: &Path) -> image::RgbImage {
    let status = Command::new("sh")
        .arg("-c")
        .arg(format!("xwd -root -silent | convert xwd:- png:'{}'", out.display()))
        .env("DISPLAY", display)
        .status()
        .expect("cannot run xwd | convert");
    assert!(status.success(), "xwd | convert failed");
    image::open(out).expect("the X screenshot is a PNG").to_rgb8()
}

/// A screenshot of the resting window: the pointer moved to the window's
/// bottom-right corner (no hover highlight), a few frames let past, the
/// picture taken into `dir`, and kept as `{OCTOVOX_KEEP_SHOTS}/{name}.png`
/// when that is set.
pub fn resting_shot(display: &str, window: &str, dir: &Path, name: &str) -> image::RgbImage {
    xdotool(display, &["mousemove", "--window", window, "790", "590"]);
    std::thread::sleep(Duration::from_millis(800));
    let image = screenshot_x(display, &dir.join(format!("{name}.png")));
    if let Ok(keep) = std::env::var("OCTOVOX_KEEP_SHOTS") {
        image.save(format!("{keep}/{name}.png")).unwrap();
    }
    image
}

/// Clicks window pixel (x, y) with the left button and waits for the edit.
/// A left drag from `from` to `to` with the real mouse: press, eight
/// moves 60 ms apart along the straight line, release.
pub fn drag(display: &str, window: &str, from: (u32, u32), to: (u32, u32)) {
    let at = |p: (i64, i64)| [p.0.to_string(), p.1.to_string()];
    let (x, y) = (i64::from(from.0), i64::from(from.1));
    let (ex, ey) = (i64::from(to.0), i64::from(to.1));
    let [sx, sy] = at((x, y));
    xdotool(display, &["mousemove", "--window", window, &sx, &sy]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(display, &["mousedown", "1"]);
    for step in 1..=8 {
        let [px, py] = at((x + (ex - x) * step / 8, y + (ey - y) * step / 8));
        xdotool(display, &["mousemove", "--window", window, &px, &py]);
        std::thread::sleep(Duration::from_millis(60));
    }
    xdotool(display, &["mouseup", "1"]);
}

pub fn click(display: &str, window: &str, lines: &mut Lines, x: u32, y: u32) -> u64 {
    xdotool(display, &["mousemove", "--window", window, &x.to_string(), &y.to_string()]);
    // Let a frame show the hover highlight first (not needed for the edit).
    std::thread::sleep(Duration::from_millis(300));
    xdotool(display, &["click", "1"]);
    let line = lines.wait_for("edit:", Duration::from_secs(30));
    line.split_whitespace().nth(1).and_then(|n| n.parse().ok()).expect("edit line: `edit: N bytes written …`")
}

/// Answers the window's file browser (tests turn native dialogs off):
/// waits for it and types `path` into it ([`type_in_browser`]).
pub fn answer_browser(display: &str, window: &str, lines: &mut Lines, size: (u32, u32), path: &Path) {
    wait_for_browser(lines);
    type_in_browser(display, window, size, path);
}

/// Waits until the file browser is up and drawn.
pub fn wait_for_browser(lines: &mut Lines) {
    lines.wait_for("file dialog: browser", Duration::from_secs(30));
    std::thread::sleep(Duration::from_millis(700));
}

/// Clicks the open browser's file-name field, types `path` over what is
/// there and presses Return. The browser is centred 20 px below the middle
/// of a window of `size` and is 300 px tall, its name field 105 px below
/// its centre (`src/app/browser.rs`).
pub fn type_in_browser(display: &str, window: &str, size: (u32, u32), path: &Path) {
    let (x, y) = (size.0 / 2 - 30, size.1 / 2 + 20 + 105);
    xdotool(display, &["mousemove", "--window", window, &x.to_string(), &y.to_string()]);
    // A frame with the pointer over the browser first: egui decides from
    // the last frame whether a click is its own or the scene's.
    std::thread::sleep(Duration::from_millis(300));
    xdotool(display, &["click", "1"]);
    std::thread::sleep(Duration::from_millis(300));
    xdotool(display, &["key", "ctrl+a"]);
    xdotool(display, &["type", &path.display().to_string()]);
    xdotool(display, &["key", "Return"]);
}

/// Ctrl+S, until the app says it saved `file`. Sent again after a while:
/// on a loaded machine an Escape that takes the keyboard focus from a panel
/// widget and the Ctrl+S after it can reach the window before egui's next
/// frame has seen the Escape, and egui then takes the Ctrl+S as its own.
pub fn save(display: &str, lines: &mut Lines, file: &Path) {
    let mut line = None;
    for _ in 0..6 {
        xdotool(display, &["key", "ctrl+s"]);
        line = lines.try_wait_for("saved:", Duration::from_secs(5));
        if line.is_some() {
            break;
        }
    }
    let line = line.unwrap_or_else(|| panic!("no `saved:` line after six Ctrl+S; saw {:?}", lines.seen));
    assert!(line.ends_with(&*file.file_name().unwrap().to_string_lossy()), "{line}");
}

/// Starts the real binary on `display` in `dir`, stdout piped to a
/// [`Lines`] and stderr to a file (shown if the app dies early). Native
/// file dialogs are off (a desktop's would wait for a person); the
/// recent-files list lives in `dir`.
pub fn spawn_app(display: &str, dir: &Path, args: &[String]) -> (KillOnDrop, Lines, PathBuf) {
    spawn_app_with(display, dir, args, &[("OCTOVOX_NO_NATIVE_DIALOGS", "1")])
}

/// [`spawn_app`] with these environment variables (and native dialogs as
/// the machine has them).
pub fn spawn_app_with(
    display: &str,
    dir: &Path,
    args: &[String],
    env: &[(&str, &str)],
) -> (KillOnDrop, Lines, PathBuf) {
    let stderr_path = dir.join("octovox.stderr");
    let runtime_dir = dir.join("xdg");
    std::fs::create_dir_all(&runtime_dir).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_octovox"))
        .args(args)
        .current_dir(dir)
        .env("DISPLAY", display)
        .env("XDG_RUNTIME_DIR", &runtime_dir)
        .env("XDG_CONFIG_HOME", dir.join("config"))
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("DBUS_SESSION_BUS_ADDRESS")
        .envs(env.iter().copied())
        .stdout(Stdio::piped())
        .stderr(std::fs::File::create(&stderr_path).unwrap())
        .spawn()
        .expect("cannot start octovox");
    let lines = Lines::new(&mut child);
    (KillOnDrop(child, "octovox"), lines, stderr_path)
}

/// [`spawn_app`], then waits for the window to be ready and gives it the
/// keyboard focus (without a window manager nothing does): the app, its
/// stdout lines and its window id.
pub fn open_ready(display: &str, dir: &Path, args: &[String]) -> (KillOnDrop, Lines, String) {
    open_ready_with(display, dir, args, &[("OCTOVOX_NO_NATIVE_DIALOGS", "1")])
}

/// [`open_ready`] with these environment variables ([`spawn_app_with`]).
pub fn open_ready_with(
    display: &str,
    dir: &Path,
    args: &[String],
    env: &[(&str, &str)],
) -> (KillOnDrop, Lines, String) {
    let (mut app, mut lines, stderr_path) = spawn_app_with(display, dir, args, env);
    let window = find_window(display, &mut app, &stderr_path);
    lines.wait_for("octovox: ready", Duration::from_secs(90));
    xdotool(display, &["windowfocus", "--sync", &window]);
    (app, lines, window)
}

/// The window's arguments for `file` seen through `camera` at the tests'
/// size, then `extra`.
pub fn document_args(file: &Path, camera: &Camera, extra: &[&str]) -> Vec<String> {
    let base = [file.display().to_string(), "--size".into(), format!("{WIDTH}x{HEIGHT}"), camera_arg(camera)];
    base.into_iter().chain(extra.iter().map(|a| (*a).to_string())).collect()
}

/// `--camera=EX,EY,EZ:TX,TY,TZ` for a camera.
pub fn camera_arg(camera: &Camera) -> String {
    let (e, t) = (camera.eye, camera.target);
    format!("--camera={},{},{}:{},{},{}", e.x, e.y, e.z, t.x, t.y, t.z)
}

/// A writable copy of `torus64.vox` in a new folder, the scene it holds and
/// a camera framing it: the document the window tests edit.
pub fn torus_document() -> (tempfile::TempDir, PathBuf, octovox::scene::Scene, Camera) {
    require_window_tools();
    let source = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/assets/vox/seed/torus64.vox");
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("torus.vox");
    super::copy_writable(&source, &file);
    let original = octovox::io::load_scene(&file, 0).unwrap();
    let (lo, hi) = original.solid_bounds().unwrap();
    let camera = Camera::framing(lo, hi, 50.0);
    (dir, file, original, camera)
}
