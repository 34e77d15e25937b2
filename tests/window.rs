//! The real window: `illumlab view` under Xvfb with Mesa's software Vulkan renders the scene into a window that
//! a screenshot can see. Skipped, with a message, where xvfb-run or ImageMagick's `import` is missing
//! (`.ci/run` installs both).

use std::path::Path;
use std::process::Command;

fn have(tool: &str) -> bool {
    Command::new("sh").args(["-c", &format!("command -v {tool}")]).output().is_ok_and(|o| o.status.success())
}

#[test]
fn the_viewer_window_opens_and_shows_the_render() {
    if !(have("xvfb-run") && have("import")) {
        eprintln!("SKIPPED: xvfb-run or import (ImageMagick) is not installed; .ci/run installs them");
        return;
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let runtime = dir.path().join("runtime");
    std::fs::create_dir(&runtime).expect("runtime dir");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&runtime, std::fs::Permissions::from_mode(0o700)).expect("chmod");
    }
    let shot = dir.path().join("shot.png");
    let log = dir.path().join("viewer.log");
    // The window must still be alive when captured: `kill` fails on a process that has exited.
    let script = format!(
        "'{bin}' view cornell-box --size 96x96 --exposure 1 > '{log}' 2>&1 & pid=$!; sleep 8; \
         import -window root '{shot}' && kill $pid",
        bin = env!("CARGO_BIN_EXE_illumlab"),
        log = log.display(),
        shot = shot.display()
    );
    let status = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x640x24", "sh", "-c", &script])
        .env("XDG_RUNTIME_DIR", &runtime)
        .status()
        .expect("xvfb-run runs");
    let log_text = std::fs::read_to_string(&log).unwrap_or_default();
    assert!(status.success(), "the viewer exited early or the capture failed; its output:\n{log_text}");
    let image = image::open(Path::new(&shot)).expect("a PNG screenshot").to_rgb8();
    // The Cornell box's red and green walls are on screen.
    let (mut red, mut green) = (0, 0);
    for p in image.pixels() {
        let [r, g, b] = p.0.map(i32::from);
        // Wall colours after exposure and sRGB: red ≈ (150, 40, 15), green ≈ (75, 110, 25).
        red += (r > 60 && r > 2 * g && r > 2 * b) as u32;
        green += (g > 60 && 4 * g > 5 * r && g > 2 * b) as u32;
    }
    assert!(red > 200 && green > 200, "no Cornell box in the window (red {red}, green {green} pixels)");
}
