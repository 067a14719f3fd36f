//! `palette load`, `palette save`, `palette preset` and `expect palette` in
//! `octovox replay`: each format read from a file written the way another
//! program writes it (GIMP's .gpl, Lospec's .hex with Windows line ends, a
//! PNG made with the `image` crate, not octovox), the saved files read back
//! by an independent reader, undo, and a recording that needs no file.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

use std::path::Path;
use std::process::Command;

use octovox::scene::Palette;

/// Runs `script` (in `dir`) on the CPU; its stdout and stderr, and whether it passed.
fn replay(dir: &Path, script: &str) -> (bool, String) {
    let path = dir.join("palette.ovr");
    std::fs::write(&path, script).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_octovox")).args(["replay", "--cpu", path.to_str().unwrap()]).output();
    let out = out.unwrap();
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

/// `expect palette` lines for the default palette's entries `indices`.
fn expect_default(indices: impl IntoIterator<Item = u8>) -> String {
    let palette = Palette::default();
    indices
        .into_iter()
        .map(|i| {
            let [r, g, b, _] = palette.color(i);
            format!("expect palette {i} {r} {g} {b}\n")
        })
        .collect()
}

#[test]
fn files_of_other_programs_load_and_leave_the_other_entries() {
    let dir = tempfile::tempdir().unwrap();
    // As GIMP writes a palette: header, name, columns, comment, tab-separated names.
    let gpl = "GIMP Palette\nName: Test\nColumns: 4\n#\n255   0   0\tRed\n  0 255   0\tGreen\n 10  20  30\tUntitled\n";
    std::fs::write(dir.path().join("gimp.gpl"), gpl).unwrap();
    // As Lospec serves a .hex: lower-case digits, here with Windows line ends.
    std::fs::write(dir.path().join("lospec.hex"), "1a1c2c\r\n5D275D\r\nb13e53\r\n").unwrap();
    // A 256×1 PNG whose pixel k is (k, 255 − k, 7): index k + 1.
    let strip = image::RgbImage::from_fn(256, 1, |x, _| image::Rgb([x as u8, 255 - x as u8, 7]));
    strip.save(dir.path().join("magica.png")).unwrap();
    let script = format!(
        "new\npalette load gimp.gpl\nexpect palette 1 255 0 0\nexpect palette 3 10 20 30\n{}\
         undo\n{}\
         palette load lospec.hex\nexpect palette 1 26 28 44\nexpect palette 2 93 39 93\nexpect palette 3 177 62 83\n{}\
         palette load magica.png\nexpect palette 1 0 255 7\nexpect palette 200 199 56 7\nexpect palette 255 254 1 7\n\
         palette preset pico8\nexpect palette 2 29 43 83\nexpect palette 16 255 204 170\n{}",
        expect_default(4..=6),
        expect_default(1..=3),
        expect_default([4, 255]),
        // The preset holds 16 colours: index 17 on keeps the PNG's.
        "expect palette 17 16 239 7\n",
    );
    let (ok, text) = replay(dir.path(), &script);
    assert!(ok && text.contains(" 0 failed"), "{text}");
}

#[test]
fn saved_palettes_read_back_in_every_format_and_by_another_reader() {
    let dir = tempfile::tempdir().unwrap();
    let script = "new\npalette preset sweetie16\nrgb 200 1 2 3\n\
                  palette save out.png\npalette save out.hex\npalette save out.gpl\n\
                  new\npalette load out.gpl\nexpect palette 1 26 28 44\nexpect palette 200 1 2 3\n\
                  new\npalette load out.hex\nexpect palette 16 51 60 87\nexpect palette 200 1 2 3\n\
                  new\npalette load out.png\nexpect palette 13 244 244 244\nexpect palette 200 1 2 3\n";
    let (ok, text) = replay(dir.path(), script);
    assert!(ok && text.contains("6 passed, 0 failed"), "{text}");
    // The PNG is MagicaVoxel's 256×1, pixel k index k + 1, read by the `image` crate.
    let png = image::open(dir.path().join("out.png")).unwrap().to_rgba8();
    assert_eq!(png.dimensions(), (256, 1));
    assert_eq!((png.get_pixel(0, 0).0, png.get_pixel(199, 0).0), ([26, 28, 44, 255], [1, 2, 3, 255]));
    // The text formats, read here line by line.
    let hex = std::fs::read_to_string(dir.path().join("out.hex")).unwrap();
    assert_eq!((hex.lines().count(), hex.lines().nth(199)), (255, Some("010203")));
    let gpl = std::fs::read_to_string(dir.path().join("out.gpl")).unwrap();
    assert!(gpl.starts_with("GIMP Palette\n"), "{gpl}");
    let rows: Vec<Vec<u8>> = gpl
        .lines()
        .filter(|l| l.starts_with(|c: char| c.is_ascii_digit() || c == ' '))
        .map(|l| l.split_whitespace().take(3).map(|w| w.parse().unwrap()).collect())
        .collect();
    assert_eq!((rows.len(), &rows[199]), (255, &vec![1, 2, 3]));
}

#[test]
fn bad_palette_lines_and_files_say_why_and_change_nothing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("broken.hex"), "ff0000\nxyz\n").unwrap();
    for (line, message) in [
        ("palette load broken.hex", "broken.hex:2: expected a colour RRGGBB, found 'xyz'"),
        ("palette load missing.gpl", "cannot read"),
        ("palette load p.act", "a palette file is .png (MagicaVoxel, 256×1), .hex (Lospec) or .gpl (GIMP)"),
        ("palette save p.jpg", "a palette file is .png"),
        ("palette set 255 ff0000 00ff00", "colours past palette index 255"),
        ("palette set 3 red", "expected a colour RRGGBB, found 'red'"),
        ("palette preset rainbow", "expected a preset (magicavoxel, pico8, sweetie16, gray), found 'rainbow'"),
        ("expect palette 0 1 2 3", "palette index 0 is outside 1..=255"),
    ] {
        let (ok, text) = replay(dir.path(), &format!("new\n{line}\n{}", expect_default([1])));
        assert!(!ok, "{line}: {text}");
        assert!(text.contains(message), "{line}: {text}");
    }
}

/// A recording keeps what a `palette load` did as `palette set`: replayed
/// after the file is gone, it makes the same palette.
#[test]
fn a_recording_of_a_load_needs_no_file() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("p.hex"), "102030\n405060\n").unwrap();
    let path = dir.path().join("p.ovr");
    let script = octovox::script::parse_script(&path, "new\npalette load p.hex\n").unwrap();
    let mut runner = octovox::replay::Runner::new(octovox::replay::RunnerMode::Cpu);
    let recording = dir.path().join("rec.ovr");
    let mut recorder = octovox::replay::Recorder::create(&recording).unwrap();
    for line in &script.lines {
        if let octovox::replay::StepResult::Ran(ran) = runner.step(dir.path(), line).unwrap() {
            let tools = runner.editor.tools;
            let changed = ran.outcome == octovox::editor::Outcome::Changed;
            recorder.ran(&ran.line, &tools, &octovox::camera::Camera::default(), changed).unwrap();
        }
    }
    // A file that fails to read changes nothing.
    let bad = octovox::script::parse_script(&path, "palette load broken.gpl\n").unwrap();
    std::fs::write(dir.path().join("broken.gpl"), "GIMP Palette\n1 2 3\n4 5\n").unwrap();
    let before = runner.editor.scene.palette.clone();
    assert!(runner.step(dir.path(), &bad.lines[0]).unwrap_err().to_string().contains("broken.gpl:3:"));
    assert_eq!(runner.editor.scene.palette, before);
    assert_eq!(runner.editor.history.steps(), (1, 0), "the load is one undo step; the failed one none");
    drop(recorder);
    std::fs::remove_file(dir.path().join("p.hex")).unwrap();
    let recorded = std::fs::read_to_string(&recording).unwrap();
    assert!(recorded.contains("palette set 1 102030 405060"), "{recorded}");
    let (ok, text) = replay(dir.path(), &format!("new\n{recorded}expect palette 2 64 80 96\n"));
    assert!(ok, "{text}");
}

/// `palette save` replaced the palette the run had loaded, and any existing
/// .gpl/.hex/.png, without `--force` (issue 48, item 6): now it refuses and
/// the file keeps its bytes; `replay --force` replaces it.
#[test]
fn palette_save_replaces_an_existing_file_only_with_force() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["mine.hex", "mine.gpl", "mine.png"] {
        let path = dir.path().join(name);
        let before = match name {
            "mine.png" => {
                image::RgbImage::from_pixel(256, 1, image::Rgb([9, 8, 7])).save(&path).unwrap();
                std::fs::read(&path).unwrap()
            }
            "mine.gpl" => b"GIMP Palette\n1 2 3\n".to_vec(),
            _ => b"010203\n".to_vec(),
        };
        std::fs::write(&path, &before).unwrap();
        let script = format!("new\npalette load {name}\nrgb 5 200 100 50\npalette save {name}\n");
        let (ok, text) = replay(dir.path(), &script);
        assert!(!ok && text.contains("already exists; refusing to replace it (--force replaces it)"), "{text}");
        assert_eq!(std::fs::read(&path).unwrap(), before, "{name} changed");
        let script_path = dir.path().join("palette.ovr");
        let out = Command::new(env!("CARGO_BIN_EXE_octovox"))
            .args(["replay", "--cpu", "--force", script_path.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_ne!(std::fs::read(&path).unwrap(), before, "{name} with --force");
    }
}

/// Issue 48, item 14: a palette file with a UTF-8 byte-order mark or
/// old-Mac (CR-only) line ends was refused quoting an invisible character;
/// it reads as its clean twin. An empty .hex was taken as no colours; it is
/// refused. A PNG whose header claims 2^31 × 2^31 said "Memory limit
/// exceeded"; it names its size and the limit.
#[test]
fn odd_but_fair_palette_files_read_like_their_twins_and_bad_ones_say_why() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bom.hex"), "\u{feff}102030\n405060\n").unwrap();
    std::fs::write(dir.path().join("cr.hex"), "102030\r405060\r").unwrap();
    std::fs::write(dir.path().join("bom.gpl"), "\u{feff}GIMP Palette\r\nName: x\r\n16 32 48 a\r\n64 80 96 b\r\n")
        .unwrap();
    std::fs::write(dir.path().join("cr.gpl"), "GIMP Palette\rName: x\r16 32 48\r64 80 96\r").unwrap();
    for name in ["bom.hex", "cr.hex", "bom.gpl", "cr.gpl"] {
        let script = format!("new\npalette load {name}\nexpect palette 1 16 32 48\nexpect palette 2 64 80 96\n");
        let (ok, text) = replay(dir.path(), &script);
        assert!(ok && text.contains("2 passed, 0 failed"), "{name}: {text}");
    }
    std::fs::write(dir.path().join("empty.hex"), "\n\n").unwrap();
    let (ok, text) = replay(dir.path(), "new\npalette load empty.hex\n");
    assert!(!ok && text.contains("empty.hex") && text.contains("holds no colour"), "{text}");
    // A PNG signature and an IHDR claiming 2^31 × 2^31 (CRC left wrong: the
    // size must be read, and refused, before anything else).
    let mut png = vec![0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n', 0, 0, 0, 13];
    png.extend_from_slice(b"IHDR");
    png.extend_from_slice(&(1u32 << 31).to_be_bytes());
    png.extend_from_slice(&(1u32 << 31).to_be_bytes());
    png.extend_from_slice(&[8, 2, 0, 0, 0, 0, 0, 0, 0]);
    std::fs::write(dir.path().join("huge.png"), png).unwrap();
    let (ok, text) = replay(dir.path(), "new\npalette load huge.png\n");
    assert!(!ok && text.contains("2147483648×2147483648") && text.contains("256×1"), "{text}");
}
