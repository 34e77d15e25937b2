//! End-to-end tests of the `illumlab` binary: bad input fails cleanly (one line on stderr naming the file or
//! option, exit code 1 or 2, no panic, no output or temporary file left behind), a scene without emitters gives a
//! warning and a black image, `illumlab strategies` lists the strategies, and the image depends only on (scene,
//! options, seed). Renders are tiny so that the whole file runs in a few seconds in the debug profile.

mod common;

use std::ffi::{OsStr, OsString};
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use tempfile::TempDir;

// ---------------------------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------------------------

/// Runs the binary with `args` and captures everything.
fn run<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    Command::new(env!("CARGO_BIN_EXE_illumlab")).args(args).output().expect("cannot start illumlab")
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Arguments of `illumlab render SCENE … -o OUT`, with small defaults. `options` replace a default of the same
/// name or are added (clap rejects an option given twice, so a test cannot just append `--spp 0`).
fn render_args(scene: impl AsRef<OsStr>, out: &Path, options: &[(&str, &str)]) -> Vec<OsString> {
    let mut opts = vec![("--strategy", "cosine"), ("--spp", "1"), ("--size", "4x4")];
    for &(name, value) in options {
        match opts.iter_mut().find(|(n, _)| *n == name) {
            Some(o) => o.1 = value,
            None => opts.push((name, value)),
        }
    }
    let mut args: Vec<OsString> = vec!["render".into(), scene.as_ref().to_owned()];
    for (name, value) in opts {
        args.extend([name.into(), value.into()]);
    }
    args.extend(["-o".into(), out.as_os_str().to_owned()]);
    args
}

/// Asserts a successful run, showing stderr otherwise.
fn assert_success(output: &Output) {
    assert!(output.status.success(), "expected success, got {:?}; stderr:\n{}", output.status, stderr(output));
}

/// Asserts the failure contract on the process itself: exit code 1 or 2 (not a signal, not a panic's 101), no
/// panic message, and stderr exactly one non-empty `error…` line containing every string of `must_contain`.
/// Returns that line.
fn assert_one_line_error(output: &Output, must_contain: &[&str]) -> String {
    let err = stderr(output);
    let code = output.status.code();
    assert!(matches!(code, Some(1 | 2)), "expected exit code 1 or 2, got {:?}; stderr:\n{err}", output.status);
    assert!(!err.contains("panicked"), "the binary panicked:\n{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(lines.len(), 1, "expected exactly one line on stderr, got {}:\n{err}", lines.len());
    let line = lines[0];
    assert!(line.trim().starts_with("error"), "the stderr line should start with 'error': {line:?}");
    for needle in must_contain {
        assert!(line.contains(needle), "the error line should name {needle:?}: {line:?}");
    }
    line.to_string()
}

/// Names of temporary files (`.NAME.PID.tmp`, see `render::output`) in `dir`.
fn temporary_files(dir: &Path) -> Vec<String> {
    let Ok(entries) = fs::read_dir(dir) else { return Vec::new() };
    entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.') && n.ends_with(".tmp"))
        .collect()
}

/// Asserts that a failed render left neither `out` nor a temporary file beside it.
fn assert_no_output(out: &Path) {
    assert!(!out.exists(), "a failed render left {} behind", out.display());
    if let Some(dir) = out.parent() {
        let stray = temporary_files(dir);
        assert!(stray.is_empty(), "a failed render left temporary files in {}: {stray:?}", dir.display());
    }
}

/// Renders `scene` to `out` expecting failure, and checks the whole contract. Returns the error line.
fn assert_render_fails(
    scene: impl AsRef<OsStr>,
    out: &Path,
    options: &[(&str, &str)],
    must_contain: &[&str],
) -> String {
    let output = run(render_args(scene, out, options));
    let line = assert_one_line_error(&output, must_contain);
    assert_no_output(out);
    line
}

/// A small valid scene: a grey floor quad lit by a downward-facing square light above it. Each bad-scene test
/// changes exactly one thing in it, so that the failure can only come from that change (the control test
/// `test_scene_is_valid` renders it unchanged).
use common::SMALL_SCENE_TOML as TOML;

const OBJ: &str = "\
mtllib scene.mtl
o floor
v -1.0 0.0 1.0
v 1.0 0.0 1.0
v 1.0 0.0 -1.0
v -1.0 0.0 -1.0
usemtl grey
f 1 2 3
f 1 3 4
o light
v -0.25 1.5 -0.25
v 0.25 1.5 -0.25
v 0.25 1.5 0.25
v -0.25 1.5 0.25
usemtl light
f 5 6 7
f 5 7 8
";

const MTL: &str = "\
newmtl grey
Kd 0.5 0.5 0.5
Ks 0.0 0.0 0.0
Ns 1.0

newmtl light
Kd 0.0 0.0 0.0
Ks 0.0 0.0 0.0
Ns 1.0
Ke 10.0 10.0 10.0
";

/// `text` with `from` replaced by `to`; panics if `from` is absent, so that a fixture edit cannot silently turn
/// into a no-op (and the test into a test of the valid scene).
fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "fixture edit: {from:?} not found in:\n{text}");
    text.replacen(from, to, 1)
}

/// Writes `scene.toml`, `scene.obj` and `scene.mtl` into `dir`; returns the path of the TOML.
fn write_scene(dir: &Path, toml: &str, obj: &str, mtl: &str) -> PathBuf {
    for (name, text) in [("scene.toml", toml), ("scene.obj", obj), ("scene.mtl", mtl)] {
        fs::write(dir.join(name), text).expect("cannot write the test scene");
    }
    dir.join("scene.toml")
}

/// Writes the scene into a fresh folder and checks that rendering it fails cleanly, naming `must_contain`.
fn assert_bad_scene(toml: &str, obj: &str, mtl: &str, must_contain: &[&str]) -> String {
    let dir = TempDir::new().unwrap();
    let scene = write_scene(dir.path(), toml, obj, mtl);
    assert_render_fails(&scene, &dir.path().join("out.png"), &[], must_contain)
}

/// Checks that rendering the valid test scene with one bad option fails cleanly, naming `must_contain`.
fn assert_bad_option(option: &str, value: &str, must_contain: &[&str]) -> String {
    let dir = TempDir::new().unwrap();
    let scene = write_scene(dir.path(), TOML, OBJ, MTL);
    assert_render_fails(&scene, &dir.path().join("out.png"), &[(option, value)], must_contain)
}

/// Decodes a PNG into 8-bit RGB.
fn read_png(path: &Path) -> image::RgbImage {
    image::open(path).unwrap_or_else(|e| panic!("cannot decode {}: {e}", path.display())).to_rgb8()
}

/// Decodes an EXR's first RGB(A) layer: (width, height, pixels row by row).
fn read_exr(path: &Path) -> (usize, usize, Vec<[f32; 3]>) {
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| (size.width(), size.height(), vec![[0.0f32; 3]; size.area()]),
        |(w, _, pixels): &mut (usize, usize, Vec<[f32; 3]>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            pixels[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )
    .unwrap_or_else(|e| panic!("cannot decode {}: {e}", path.display()));
    image.layer_data.channel_data.pixels
}

/// The strategy names, from `illumlab strategies` (first word of each line).
fn strategy_names() -> Vec<String> {
    let output = run(["strategies"]);
    assert_success(&output);
    stdout(&output).lines().filter_map(|l| l.split_whitespace().next()).map(str::to_string).collect()
}

const BUNDLED_SCENES: [&str; 5] = ["default", "cornell-box", "veach-mis", "near-light", "occluded-light"];

// ---------------------------------------------------------------------------------------------------------------
// The control: the test scene itself is valid
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn test_scene_is_valid() {
    let dir = TempDir::new().unwrap();
    let scene = write_scene(dir.path(), TOML, OBJ, MTL);
    let out = dir.path().join("out.png");
    let output = run(render_args(&scene, &out, &[("--strategy", "emitter"), ("--spp", "4")]));
    assert_success(&output);
    assert_eq!(stderr(&output), "", "the valid test scene should render without warnings");
    let img = read_png(&out);
    assert!(img.as_raw().iter().any(|&b| b > 0), "the lit floor should not be black");
    assert!(temporary_files(dir.path()).is_empty());
}

// ---------------------------------------------------------------------------------------------------------------
// Bad scene argument
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn missing_scene_file_is_an_error() {
    let dir = TempDir::new().unwrap();
    assert_render_fails("nope/missing.toml", &dir.path().join("out.png"), &[], &["missing.toml"]);
}

#[test]
fn unknown_bundled_scene_is_an_error() {
    let dir = TempDir::new().unwrap();
    assert_render_fails("no-such-scene", &dir.path().join("out.png"), &[], &["no-such-scene"]);
}

// ---------------------------------------------------------------------------------------------------------------
// Bad TOML
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn toml_syntax_error_is_an_error() {
    assert_bad_scene(&edit(TOML, "fov_y = 45.0", "fov_y = = 45.0"), OBJ, MTL, &["scene.toml"]);
}

#[test]
fn toml_wrong_type_is_an_error() {
    assert_bad_scene(&edit(TOML, "fov_y = 45.0", "fov_y = \"wide\""), OBJ, MTL, &["scene.toml"]);
}

#[test]
fn toml_unknown_key_is_an_error() {
    // The scene format uses deny_unknown_fields: a typo must not be silently ignored.
    let line = assert_bad_scene(&edit(TOML, "fov_y = 45.0", "fov_y = 45.0\naperture = 2.0"), OBJ, MTL, &["scene.toml"]);
    assert!(line.contains("aperture"), "the error should name the unknown key: {line}");
}

#[test]
fn toml_without_camera_is_an_error() {
    let toml = "[[mesh]]\nobj = \"scene.obj\"\n";
    assert_bad_scene(toml, OBJ, MTL, &["scene.toml", "camera"]);
}

// ---------------------------------------------------------------------------------------------------------------
// Bad camera values
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn camera_fov_zero_is_an_error() {
    assert_bad_scene(&edit(TOML, "fov_y = 45.0", "fov_y = 0.0"), OBJ, MTL, &["scene.toml", "fov_y"]);
}

#[test]
fn camera_fov_180_is_an_error() {
    assert_bad_scene(&edit(TOML, "fov_y = 45.0", "fov_y = 180.0"), OBJ, MTL, &["scene.toml", "fov_y"]);
}

#[test]
fn camera_width_zero_is_an_error() {
    assert_bad_scene(&edit(TOML, "width = 8", "width = 0"), OBJ, MTL, &["scene.toml", "width"]);
}

#[test]
fn camera_eye_equal_to_target_is_an_error() {
    let toml = edit(TOML, "eye = [0.0, 1.0, 3.0]", "eye = [0.0, 0.5, 0.0]");
    assert_bad_scene(&toml, OBJ, MTL, &["scene.toml", "eye", "target"]);
}

#[test]
fn camera_up_parallel_to_view_is_an_error() {
    // target − eye = (0, −0.5, −3).
    let toml = edit(TOML, "up = [0.0, 1.0, 0.0]", "up = [0.0, -0.5, -3.0]");
    assert_bad_scene(&toml, OBJ, MTL, &["scene.toml", "up"]);
}

#[test]
fn camera_nan_eye_is_an_error() {
    let toml = edit(TOML, "eye = [0.0, 1.0, 3.0]", "eye = [nan, 1.0, 3.0]");
    assert_bad_scene(&toml, OBJ, MTL, &["scene.toml", "eye"]);
}

// ---------------------------------------------------------------------------------------------------------------
// Bad OBJ / MTL
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn missing_obj_is_an_error() {
    let toml = edit(TOML, "obj = \"scene.obj\"", "obj = \"absent.obj\"");
    assert_bad_scene(&toml, OBJ, MTL, &["absent.obj"]);
}

#[test]
fn obj_face_index_out_of_bounds_is_an_error() {
    assert_bad_scene(TOML, &edit(OBJ, "f 1 2 3", "f 1 2 99"), MTL, &["scene.obj"]);
}

#[test]
fn obj_garbage_vertex_is_an_error() {
    assert_bad_scene(TOML, &edit(OBJ, "v -1.0 0.0 1.0", "v 1 2 x"), MTL, &["scene.obj"]);
}

#[test]
fn obj_nan_vertex_is_an_error() {
    assert_bad_scene(TOML, &edit(OBJ, "v -1.0 0.0 1.0", "v nan 0 0"), MTL, &["scene.obj"]);
}

#[test]
fn missing_mtl_is_a_warning_and_renders_with_the_default_material() {
    let dir = TempDir::new().unwrap();
    let scene = write_scene(dir.path(), TOML, &edit(OBJ, "mtllib scene.mtl", "mtllib absent.mtl"), MTL);
    let out = dir.path().join("out.png");
    let output = run(render_args(&scene, &out, &[("--spp", "1")]));
    assert_success(&output);
    let err = stderr(&output);
    assert!(
        err.lines().any(|l| l.contains("warning") && l.contains("absent.mtl") && l.contains("default grey")),
        "no warning naming the missing file:\n{err}"
    );
    assert!(out.is_file());
}

#[test]
fn mtl_malformed_kd_is_an_error() {
    // Two numbers where three are expected: tobj 4.0.5 panics on this (parse_float3 unwraps), so the loader has to
    // catch it before tobj does.
    assert_bad_scene(TOML, OBJ, &edit(MTL, "Kd 0.5 0.5 0.5", "Kd 1 2"), &["scene.mtl"]);
}

#[test]
fn mtl_negative_kd_is_an_error() {
    // The value at fault is in the MTL, so the line should name the MTL (and the field), not only the material.
    assert_bad_scene(TOML, OBJ, &edit(MTL, "Kd 0.5 0.5 0.5", "Kd -0.5 0.5 0.5"), &["scene.mtl", "Kd", "grey"]);
}

#[test]
fn mtl_negative_ns_is_an_error() {
    assert_bad_scene(TOML, OBJ, &edit(MTL, "Ns 1.0", "Ns -5.0"), &["scene.mtl", "Ns", "grey"]);
}

#[test]
fn override_of_unknown_material_is_an_error() {
    let toml = format!("{TOML}[mesh.materials.chrome]\nks = [0.5, 0.5, 0.5]\n");
    assert_bad_scene(&toml, OBJ, MTL, &["chrome"]);
}

// ---------------------------------------------------------------------------------------------------------------
// Bad options
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn unknown_strategy_is_an_error() {
    assert_bad_option("--strategy", "bogus", &["--strategy", "bogus"]);
}

#[test]
fn spp_zero_is_an_error() {
    assert_bad_option("--spp", "0", &["--spp"]);
}

#[test]
fn spp_negative_is_an_error() {
    // Unless the option allows negative numbers, clap takes "-3" for an unknown flag and its message does not name
    // --spp.
    assert_bad_option("--spp", "-3", &["--spp"]);
}

#[test]
fn spp_not_a_number_is_an_error() {
    assert_bad_option("--spp", "abc", &["--spp"]);
}

#[test]
fn size_zero_width_is_an_error() {
    assert_bad_option("--size", "0x5", &["--size"]);
}

#[test]
fn size_without_height_is_an_error() {
    assert_bad_option("--size", "10", &["--size"]);
}

#[test]
fn size_not_numbers_is_an_error() {
    assert_bad_option("--size", "axb", &["--size"]);
}

#[test]
fn unknown_light_selection_is_an_error() {
    assert_bad_option("--light-selection", "nearest", &["--light-selection"]);
}

#[test]
fn nan_exposure_is_an_error() {
    assert_bad_option("--exposure", "nan", &["--exposure"]);
}

#[test]
fn zero_threads_is_an_error() {
    assert_bad_option("--threads", "0", &["--threads"]);
}

// ---------------------------------------------------------------------------------------------------------------
// Bad output paths
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn unsupported_output_extension_is_an_error() {
    let dir = TempDir::new().unwrap();
    assert_render_fails("cornell-box", &dir.path().join("out.jpg"), &[], &["out.jpg"]);
}

#[test]
fn output_into_missing_folder_is_an_error() {
    let dir = TempDir::new().unwrap();
    assert_render_fails("cornell-box", &dir.path().join("missing_dir/out.png"), &[], &["missing_dir", "out.png"]);
}

#[test]
fn output_below_a_regular_file_is_an_error() {
    // Fails for every user, root included: a file cannot contain another.
    let dir = TempDir::new().unwrap();
    fs::write(dir.path().join("some_file.txt"), "not a folder").unwrap();
    assert_render_fails("cornell-box", &dir.path().join("some_file.txt/out.png"), &[], &["some_file.txt"]);
    assert_eq!(fs::read_to_string(dir.path().join("some_file.txt")).unwrap(), "not a folder");
    assert!(temporary_files(dir.path()).is_empty());
}

#[cfg(target_os = "linux")]
#[test]
fn output_where_files_cannot_be_created_is_an_error() {
    // /proc is a folder in which nobody, root included, can create a file: this reaches the "cannot write"
    // branch (the folder exists), which the chmod test below cannot reach when the tests run as root.
    let out = Path::new("/proc/illumlab-cli-test.png");
    assert_render_fails("cornell-box", out, &[], &["illumlab-cli-test.png"]);
}

#[cfg(unix)]
#[test]
fn output_into_read_only_folder_is_an_error() {
    use std::os::unix::fs::PermissionsExt;
    let dir = TempDir::new().unwrap();
    let locked = dir.path().join("locked");
    fs::create_dir(&locked).unwrap();
    fs::set_permissions(&locked, fs::Permissions::from_mode(0o555)).unwrap();
    // Root (and CAP_DAC_OVERRIDE) ignores the mode: then the folder is writable and there is nothing to test.
    let probe = locked.join("probe");
    if fs::write(&probe, "").is_ok() {
        let _ = fs::remove_file(&probe);
        eprintln!("skipped: a 0o555 folder is writable by this user (root?); see output_below_a_regular_file_…");
    } else {
        assert_render_fails("cornell-box", &locked.join("out.png"), &[], &["out.png"]);
    }
    // Let TempDir delete it.
    fs::set_permissions(&locked, fs::Permissions::from_mode(0o755)).unwrap();
}

// ---------------------------------------------------------------------------------------------------------------
// A scene without emitters is valid: a warning and a black image
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn scene_without_emitter_warns_and_renders_black() {
    let dir = TempDir::new().unwrap();
    let obj = OBJ.split("o light").next().unwrap(); // the floor alone
    let mtl = MTL.split("newmtl light").next().unwrap();
    let scene = write_scene(dir.path(), TOML, obj, mtl);
    for (file, strategy) in [("black.png", "emitter"), ("black.exr", "cosine")] {
        let out = dir.path().join(file);
        let output = run(render_args(&scene, &out, &[("--strategy", strategy), ("--spp", "2"), ("--size", "8x8")]));
        assert_success(&output);
        let err = stderr(&output);
        assert!(err.lines().any(|l| l.contains("warning") && l.contains("no emitter")), "no warning:\n{err}");
        assert!(!err.contains("error"), "a scene without emitters is valid:\n{err}");
        if file.ends_with(".png") {
            let img = read_png(&out);
            assert_eq!(img.dimensions(), (8, 8));
            assert!(img.as_raw().iter().all(|&b| b == 0), "the PNG should be black");
        } else {
            let (w, h, pixels) = read_exr(&out);
            assert_eq!((w, h), (8, 8));
            assert!(pixels.iter().flatten().all(|&v| v == 0.0), "the EXR should be black");
        }
    }
}

// ---------------------------------------------------------------------------------------------------------------
// `illumlab strategies`
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn strategies_lists_one_line_per_strategy() {
    let output = run(["strategies"]);
    assert_success(&output);
    let text = stdout(&output);
    let lines: Vec<&str> = text.lines().collect();
    for line in &lines {
        let mut words = line.splitn(2, char::is_whitespace);
        let name = words.next().unwrap_or("");
        let description = words.next().unwrap_or("").trim();
        assert!(!name.is_empty() && !line.starts_with(char::is_whitespace), "line without a name: {line:?}");
        assert!(!description.is_empty(), "strategy {name:?} has no description: {line:?}");
    }
    for name in ["uniform", "cosine", "brdf", "emitter"] {
        let count = lines.iter().filter(|l| l.split_whitespace().next() == Some(name)).count();
        assert_eq!(count, 1, "{name} should start exactly one line of:\n{text}");
    }
}

#[test]
fn a_reader_that_closes_the_pipe_early_is_not_an_error() {
    // `illumlab strategies | head -0`: stdout is closed before illumlab writes.
    let mut child = Command::new(env!("CARGO_BIN_EXE_illumlab"))
        .arg("strategies")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("cannot start illumlab");
    drop(child.stdout.take());
    let output = child.wait_with_output().expect("wait");
    assert!(output.status.success(), "exit status {:?}", output.status);
    assert!(!stderr(&output).contains("panicked"), "{}", stderr(&output));
}

// ---------------------------------------------------------------------------------------------------------------
// Determinism and the written image
// ---------------------------------------------------------------------------------------------------------------

/// Renders cornell-box at 64x64 (four EXR blocks), 8 spp (enough for the per-pixel camera-ray cones), to `out`
/// with the given seed and thread count; returns the file's bytes.
fn render_cornell(out: &Path, seed: &str, threads: &str) -> Vec<u8> {
    let options = [("--size", "64x64"), ("--spp", "8"), ("--seed", seed), ("--threads", threads)];
    let output = run(render_args("cornell-box", out, &options));
    assert_success(&output);
    fs::read(out).unwrap()
}

#[test]
fn image_is_the_same_with_one_or_two_threads() {
    let dir = TempDir::new().unwrap();
    let one = render_cornell(&dir.path().join("t1.exr"), "7", "1");
    for run in 0..3 {
        let two = render_cornell(&dir.path().join(format!("t2-{run}.exr")), "7", "2");
        assert!(one == two, "the EXR file differs between 1 and 2 threads (run {run})");
    }
}

#[test]
fn image_depends_on_the_seed() {
    let dir = TempDir::new().unwrap();
    let a = render_cornell(&dir.path().join("s7.exr"), "7", "2");
    let b = render_cornell(&dir.path().join("s8.exr"), "8", "2");
    assert!(a != b, "seeds 7 and 8 gave the same EXR");
}

#[test]
fn png_has_the_requested_size() {
    // The scene's camera says 256x256; --size overrides it.
    let dir = TempDir::new().unwrap();
    let out = dir.path().join("cornell.png");
    let output = run(render_args("cornell-box", &out, &[("--size", "16x16"), ("--spp", "2")]));
    assert_success(&output);
    assert_eq!(read_png(&out).dimensions(), (16, 16));
}

#[test]
fn png_row_zero_is_the_top_of_the_image() {
    // Cornell box: the light is near the top centre of the frame and is the brightest thing in it (it saturates
    // to white; the lit surfaces do not). In a flipped image it would be in the bottom rows.
    let dir = TempDir::new().unwrap();
    let out = dir.path().join("cornell.png");
    let output =
        run(render_args("cornell-box", &out, &[("--size", "32x32"), ("--spp", "16"), ("--strategy", "emitter")]));
    assert_success(&output);
    let img = read_png(&out);
    let brightness = |p: &image::Rgb<u8>| p.0.iter().map(|&c| c as u32).sum::<u32>();
    let max = img.pixels().map(brightness).max().unwrap();
    let rows: Vec<u32> = img.enumerate_pixels().filter(|(_, _, p)| brightness(p) == max).map(|(_, y, _)| y).collect();
    assert!(rows.iter().all(|&y| y < 8), "the brightest pixels should be in the top quarter, found in rows {rows:?}");
}

// ---------------------------------------------------------------------------------------------------------------
// Every bundled scene with every strategy; a bare OBJ
// ---------------------------------------------------------------------------------------------------------------

#[test]
fn every_bundled_scene_renders_with_every_strategy() {
    let dir = TempDir::new().unwrap();
    let strategies = strategy_names();
    assert!(strategies.len() >= 4, "too few strategies: {strategies:?}");
    for scene in BUNDLED_SCENES {
        for strategy in &strategies {
            let out = dir.path().join(format!("{scene}-{strategy}.exr"));
            let output = run(render_args(scene, &out, &[("--strategy", strategy), ("--size", "8x8")]));
            assert!(output.status.success(), "{scene} with {strategy} failed:\n{}", stderr(&output));
            let summary = stdout(&output);
            assert!(
                summary.contains("spp") && summary.contains("non-finite"),
                "{scene} with {strategy}: unexpected summary {summary:?}"
            );
            assert!(out.is_file(), "{scene} with {strategy}: no output file");
        }
    }
    assert!(temporary_files(dir.path()).is_empty());
}

#[test]
fn bare_obj_renders_with_an_automatic_camera() {
    let dir = TempDir::new().unwrap();
    write_scene(dir.path(), TOML, OBJ, MTL);
    let out = dir.path().join("bare.png");
    let output = run(render_args(
        dir.path().join("scene.obj"),
        &out,
        &[("--size", "8x8"), ("--spp", "4"), ("--strategy", "emitter")],
    ));
    assert_success(&output);
    let img = read_png(&out);
    assert_eq!(img.dimensions(), (8, 8));
    // The automatic camera frames the geometry: some of the lit floor is in view.
    assert!(img.as_raw().iter().any(|&b| b > 0), "the bare OBJ rendered black: the camera misses the geometry?");
}

/// A large mesh's tree and its OBJ's geometry are stored on the first load and read back on the next
/// (`scene::TreeCache`, `scene::obj_cache`, in a cache folder of the test's own); the image is the same byte for
/// byte either way, and with the caches off.
#[test]
fn a_large_mesh_tree_is_read_back_from_the_cache() {
    let dir = TempDir::new().unwrap();
    // A grid of 92 × 92 squares (16 928 triangles, above the tree cache's 16 384) under a square light, with
    // texture coordinates and normals as a scanner writes them (1.3 MB, above the OBJ cache's 1 MiB).
    let n = 92;
    let mut obj = String::from("mtllib m.mtl\nusemtl grey\n");
    for j in 0..=n {
        for i in 0..=n {
            let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
            obj += &format!("v {u:.6} {v:.6} 0.000000\nvt {u:.6} {v:.6}\nvn 0 0 1\n");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let [a, b, c, d] = [0, 1, n + 2, n + 1].map(|k| j * (n + 1) + i + 1 + k);
            obj += &format!("f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}\nf {a}/{a}/{a} {c}/{c}/{c} {d}/{d}/{d}\n");
        }
    }
    assert!(obj.len() > 1 << 20, "{} bytes", obj.len());
    obj += "usemtl light\nv 0.4 0.4 1\nv 0.6 0.4 1\nv 0.6 0.6 1\nv 0.4 0.6 1\nf -1 -2 -3 -4\n";
    fs::write(dir.path().join("grid.obj"), obj).unwrap();
    fs::write(dir.path().join("m.mtl"), "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl light\nKd 0 0 0\nKe 4 4 4\n").unwrap();
    let cache = dir.path().join("cache");
    let render = |out: &str, cache_on: &str| {
        let out = dir.path().join(out);
        let args = render_args(dir.path().join("grid.obj"), &out, &[("--strategy", "emitter"), ("--size", "8x8")]);
        let mut command = Command::new(env!("CARGO_BIN_EXE_illumlab"));
        let output = command.args(args).env("XDG_CACHE_HOME", &cache).env("ILLUMLAB_CACHE", cache_on).output().unwrap();
        assert_success(&output);
        (stdout(&output).contains("tree read from the cache"), fs::read(out).unwrap())
    };
    let (first_read, first) = render("first.exr", "on");
    let (second_read, second) = render("second.exr", "on");
    let (off_read, off) = render("off.exr", "off");
    assert!(!first_read && second_read && !off_read, "read from the cache: {first_read}, {second_read}, {off_read}");
    assert!(first == second && second == off, "the same image whether the tree was built or read");
    for folder in ["trees", "objs"] {
        let entries = fs::read_dir(cache.join("illumlab").join(folder)).unwrap().count();
        assert_eq!(entries, 1, "one entry in {folder}, no partial file left");
    }
}

// ---------------------------------------------------------------------------------------------------------------
// bench
// ---------------------------------------------------------------------------------------------------------------

fn bench_args(out: &Path, extra: &[&str]) -> Vec<OsString> {
    let mut args: Vec<OsString> = ["bench", "cornell-box", "--size", "12x12", "--spp", "1,4", "--strategies"]
        .into_iter()
        .map(OsString::from)
        .collect();
    args.push("cosine,emitter".into());
    args.extend(["--reference-spp".into(), "16".into(), "--out".into(), out.as_os_str().to_owned()]);
    args.extend(extra.iter().map(OsString::from));
    args
}

/// The RMSE column of bench.csv, per row.
fn csv_rmse(path: &Path) -> Vec<String> {
    let text = fs::read_to_string(path).expect("bench.csv");
    let header: Vec<&str> = text.lines().next().expect("header").split(',').collect();
    let col = header.iter().position(|h| *h == "rmse").expect("rmse column");
    text.lines().skip(1).map(|l| l.split(',').nth(col).expect("rmse").to_string()).collect()
}

#[test]
fn bench_writes_csv_markdown_plot_and_reference_deterministically() {
    let dir = TempDir::new().expect("temp dir");
    let out = dir.path().join("b1");
    let first = run(bench_args(&out, &[]));
    assert_success(&first);
    assert!(stdout(&first).contains("reference: MIS"), "says how the reference was made: {}", stdout(&first));
    for file in ["bench.csv", "bench.md", "convergence.png", "reference.exr", "reference.var.exr"] {
        assert!(out.join(file).exists(), "{file} missing");
    }
    let rows = csv_rmse(&out.join("bench.csv"));
    assert_eq!(rows.len(), 4, "two strategies × two budgets");
    let md = fs::read_to_string(out.join("bench.md")).expect("bench.md");
    assert!(md.contains("| cosine | 4 |") && md.contains("| emitter | 1 |"), "{md}");
    assert!(md.contains("Machine:") && md.contains("By MSE at 4 spp") && md.contains("By relMSE at 4 spp"), "{md}");
    assert!(md.contains("Measured with fixed primary hits") && md.contains("means over 8 seed(s)"), "{md}");
    assert!(md.contains("pixels (those that see an emitter) left out"), "{md}");
    assert_eq!(image::image_dimensions(out.join("convergence.png")).expect("png").0, 1200);

    // With the saved reference: no new reference, the same errors (only timings differ).
    let again = dir.path().join("b2");
    let reference = out.join("reference.exr");
    let second = run(bench_args(&again, &["--reference", reference.to_str().expect("utf-8")]));
    assert_success(&second);
    assert!(!stdout(&second).contains("reference: MIS"));
    assert_eq!(csv_rmse(&again.join("bench.csv")), rows);

    // The pictures' footprint, when asked for, and said.
    let jittered = dir.path().join("b3");
    assert_success(&run(bench_args(&jittered, &["--footprint", "jittered", "--seeds", "2"])));
    let md = fs::read_to_string(jittered.join("bench.md")).expect("bench.md");
    assert!(md.contains("Measured with jittered pixel footprint") && md.contains("means over 2 seed(s)"), "{md}");
}

#[test]
fn bench_bad_input_is_one_line() {
    let dir = TempDir::new().expect("temp dir");
    let out = dir.path().join("b");
    let o = run(bench_args(&out, &["--strategies", "nope"]));
    assert_one_line_error(&o, &["--strategies"]);
    assert_one_line_error(&run(bench_args(&out, &["--footprint", "nope"])), &["--footprint"]);
    assert_one_line_error(&run(bench_args(&out, &["--seeds", "0"])), &["--seeds"]);
    let mut zero = bench_args(&out, &[]);
    let at = zero.iter().position(|a| a == "1,4").expect("spp");
    zero[at] = "0,4".into();
    assert_one_line_error(&run(zero), &["--spp"]);
    let missing = dir.path().join("missing.exr");
    let o = run(bench_args(&out, &["--reference", missing.to_str().expect("utf-8")]));
    assert_one_line_error(&o, &["missing.exr"]);
    // A reference of another size.
    let small = dir.path().join("small.exr");
    assert_success(&run(render_args("cornell-box", &small, &[])));
    let o = run(bench_args(&out, &["--reference", small.to_str().expect("utf-8")]));
    assert_one_line_error(&o, &["small.exr", "4×4", "12×12"]);
    // An output folder that cannot be created.
    let file = dir.path().join("a-file");
    fs::write(&file, "x").expect("write");
    let o = run(bench_args(&file.join("sub"), &[]));
    assert_one_line_error(&o, &["a-file"]);
}
