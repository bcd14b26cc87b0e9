//! The real window under Xvfb: start `meshpaint Duck.glb`, drive it with xdotool (orbit,
//! toggle the wireframe, export a .glb, open a broken file, open OBJ / PLY / STL, quit) and
//! check screenshots:
//! the 3D view must match an offscreen render of the same camera within a tolerance, so a
//! blank or misplaced view fails. Screenshots go to target/test-output/app_*.png; with
//! `MESHPAINT_UPDATE_SCREENSHOTS=1` they are also copied over the committed
//! screenshots/app_*.png (`MESHPAINT_UPDATE_SCREENSHOTS=1 cargo test --test app_window`).
//!
//! Needs Xvfb, xdotool and ImageMagick (`bash .ci/run` installs them) and a Vulkan or GL
//! adapter (lavapipe without a GPU). Missing tools fail the test; they never skip it.

use std::io::Read;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

use image::RgbImage;
use meshpaint::app::editor::Editor;
use meshpaint_core::io::document::Source;
use meshpaint_render::{DrawItem, GpuMct, GpuMesh, MeshUploadOptions};

use crate::common;
use common::gpu::Gpu;
use common::{output_dir, update_screenshot, workspace_path};

/// Child processes killed when the test ends, however it ends.
struct Processes {
    children: Vec<Child>,
}

impl Drop for Processes {
    fn drop(&mut self) {
        for child in self.children.iter_mut().rev() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

fn require_tool(name: &str) {
    let found = std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|dir| dir.join(name).is_file()))
        .unwrap_or(false);
    assert!(found, "{name} is missing: install xvfb, xdotool and imagemagick (bash .ci/run does)");
}

/// Starts Xvfb on a free display; returns the display name.
fn start_xvfb(processes: &mut Processes) -> String {
    let base = 100 + std::process::id() % 300;
    for n in base..base + 40 {
        if Path::new(&format!("/tmp/.X{n}-lock")).exists() || Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
            continue;
        }
        let child = Command::new("Xvfb")
            .args([&format!(":{n}"), "-screen", "0", "1280x800x24", "-nolisten", "tcp"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start Xvfb");
        processes.children.push(child);
        let started = Instant::now();
        while started.elapsed() < Duration::from_secs(10) {
            if Path::new(&format!("/tmp/.X11-unix/X{n}")).exists() {
                return format!(":{n}");
            }
            if let Some(status) = processes.children.last_mut().and_then(|c| c.try_wait().ok().flatten()) {
                eprintln!("Xvfb :{n} exited with {status}; trying the next display");
                processes.children.pop();
                break;
            }
            std::thread::sleep(Duration::from_millis(50));
        }
    }
    panic!("could not start Xvfb on any display");
}

fn xdotool(display: &str, args: &[&str]) -> String {
    let output = Command::new("xdotool").args(args).env("DISPLAY", display).output().expect("cannot run xdotool");
    assert!(output.status.success(), "xdotool {args:?}: {}", String::from_utf8_lossy(&output.stderr));
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Pacing between input events (never to wait for the app: that is [`wait_for_log`] and
/// [`wait_for_screen`]).
fn pause(seconds: f64) {
    std::thread::sleep(Duration::from_secs_f64(seconds));
}

fn screenshot(display: &str, path: &Path) -> RgbImage {
    let status = Command::new("import")
        .args(["-window", "root"])
        .arg(path)
        .env("DISPLAY", display)
        .status()
        .expect("cannot run ImageMagick's import");
    assert!(status.success(), "import failed");
    image::open(path).expect("unreadable screenshot").to_rgb8()
}

/// The application's log so far.
fn read_log(path: &Path) -> String {
    let mut text = String::new();
    if let Ok(mut file) = std::fs::File::open(path) {
        let _ = file.read_to_string(&mut text);
    }
    text
}

/// Waits until the log contains `needle` (after `from` bytes); returns the log. Fails at
/// once if the app exits.
fn wait_for_log(path: &Path, needle: &str, from: usize, timeout: Duration, app: &mut Child) -> String {
    let started = Instant::now();
    loop {
        let log = read_log(path);
        if log.get(from..).is_some_and(|tail| tail.contains(needle)) {
            return log;
        }
        if let Ok(Some(status)) = app.try_wait() {
            panic!("the app exited ({status}) while waiting for “{needle}”:\n{log}");
        }
        assert!(started.elapsed() < timeout, "no “{needle}” in the log after {timeout:?}:\n{log}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// Starts the editor on `file` in `dir` (its stderr log at `log_path`) with `env` added.
fn start_app(display: &str, dir: &Path, log_path: &Path, file: &Path, env: &[(&str, &str)]) -> Child {
    let mut command = Command::new(env!("CARGO_BIN_EXE_meshpaint"));
    command
        .arg(file)
        .env("DISPLAY", display)
        .env("RUST_LOG", "meshpaint=info")
        .env("XDG_RUNTIME_DIR", dir)
        .env("XDG_STATE_HOME", dir)
        // Its settings file in the test's directory, never the real one.
        .env("MESHPAINT_CONFIG_DIR", dir)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(log_path).unwrap());
    for (key, value) in env {
        command.env(key, value);
    }
    command.spawn().expect("cannot start meshpaint")
}

/// The editor's window, focused.
fn focus_window(display: &str) {
    let window = xdotool(display, &["search", "--sync", "--name", "meshpaint"]);
    let window = window.lines().next().expect("no meshpaint window").trim().to_owned();
    xdotool(display, &["windowfocus", "--sync", &window]);
}

/// Screenshots (to `path`) until two in a row agree inside `rect` — the app has finished
/// drawing — and `accept` holds for the whole screenshot; returns it. Waits for state, not for
/// a fixed time: fails after `timeout` or at once if the app exits.
fn wait_for_screen(
    display: &str,
    path: &Path,
    rect: (u32, u32, u32, u32),
    what: &str,
    accept: &dyn Fn(&RgbImage) -> bool,
    app: &mut Child,
) -> RgbImage {
    let timeout = Duration::from_secs(60);
    let started = Instant::now();
    let mut previous: Option<RgbImage> = None;
    loop {
        let shot = screenshot(display, path);
        let view = crop(&shot, rect);
        if previous.as_ref().is_some_and(|p| *p == view) && accept(&shot) {
            return shot;
        }
        if let Ok(Some(status)) = app.try_wait() {
            panic!("the app exited ({status}) while waiting for {what}");
        }
        assert!(started.elapsed() < timeout, "no {what} on screen after {timeout:?} (see {})", path.display());
        previous = Some(view);
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The 3D view shows a mesh: background at the corners, not at the centre.
fn view_drawn(shot: &RgbImage, rect: (u32, u32, u32, u32)) -> bool {
    let view = crop(shot, rect);
    let (w, h) = view.dimensions();
    is_background(view.get_pixel(4, 4)) && !is_background(view.get_pixel(w / 2, h / 2))
}

/// Opens a file dialog with `keys`, waits until its path field has the keyboard focus (the
/// app logs it), replaces the field's text with `path` and confirms with Enter.
fn type_into_dialog(display: &str, log_path: &Path, keys: &str, path: &Path, app: &mut Child) {
    let from = read_log(log_path).len();
    xdotool(display, &["key", keys]);
    wait_for_log(log_path, "the path field has the keyboard focus", from, Duration::from_secs(30), app);
    // Key events reach the app in order: no pause is needed between them.
    xdotool(display, &["key", "ctrl+a"]);
    xdotool(display, &["type", "--delay", "30", &path.display().to_string()]);
    xdotool(display, &["key", "Return"]);
}

/// Waits until the app exits after Ctrl+Q; returns its status.
fn quit(display: &str, app: &mut Child) -> std::process::ExitStatus {
    xdotool(display, &["key", "ctrl+q"]);
    let started = Instant::now();
    loop {
        if let Some(status) = app.try_wait().unwrap() {
            return status;
        }
        assert!(started.elapsed() < Duration::from_secs(20), "the app did not quit on Ctrl+Q");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// The last "3D view at X,Y size WxH px" of the log.
fn view_rect(log: &str) -> (u32, u32, u32, u32) {
    let line = log.lines().rev().find(|l| l.contains("3D view at ")).expect("the app logged no 3D view");
    let rest = &line[line.find("3D view at ").unwrap() + "3D view at ".len()..];
    let mut parts = rest.split(|c: char| !c.is_ascii_digit()).filter(|s| !s.is_empty());
    let mut next = || parts.next().unwrap().parse::<u32>().unwrap();
    (next(), next(), next(), next())
}

fn crop(image: &RgbImage, (x, y, w, h): (u32, u32, u32, u32)) -> RgbImage {
    image::imageops::crop_imm(image, x, y, w, h).to_image()
}

/// The background's sRGB bytes.
fn background() -> [u8; 3] {
    let [r, g, b, _] =
        meshpaint_render::RenderSettings::DEFAULT_BACKGROUND.map(meshpaint_core::colors::format::encode_srgb8);
    [r, g, b]
}

fn is_background(pixel: &image::Rgb<u8>) -> bool {
    let bg = background();
    (0..3).all(|c| pixel[c].abs_diff(bg[c]) <= 3)
}

/// Blank-or-misplaced checks on the 3D view: background at the corners, mesh in the
/// middle, a plausible share of mesh pixels around the centre. Returns the mesh share.
fn check_view_not_blank(view: &RgbImage, name: &str) -> f64 {
    let (w, h) = view.dimensions();
    for (cx, cy) in [(4, 4), (w - 5, 4), (w - 5, h / 2)] {
        assert!(is_background(view.get_pixel(cx, cy)), "{name}: corner ({cx},{cy}) is not background");
    }
    let mut mesh = 0u64;
    let (mut sx, mut sy) = (0f64, 0f64);
    for (x, y, pixel) in view.enumerate_pixels() {
        if y < h - 30 && !is_background(pixel) {
            mesh += 1;
            sx += f64::from(x);
            sy += f64::from(y);
        }
    }
    let share = mesh as f64 / f64::from(w * (h - 30));
    assert!(share > 0.08 && share < 0.8, "{name}: the mesh covers {:.1}% of the view", share * 100.0);
    let (mx, my) = (sx / mesh as f64 / f64::from(w), sy / mesh as f64 / f64::from(h));
    assert!((mx - 0.5).abs() < 0.15 && (my - 0.5).abs() < 0.15, "{name}: mesh centroid at ({mx:.2}, {my:.2})");
    let center = view.get_pixel(w / 2, h / 2);
    assert!(!is_background(center), "{name}: no mesh at the centre of the view");
    share
}

/// Share of dark pixels among the mesh pixels (wireframe lines are dark).
fn dark_share(view: &RgbImage) -> f64 {
    let (mut mesh, mut dark) = (0u64, 0u64);
    for (_, y, pixel) in view.enumerate_pixels() {
        if y + 30 < view.height() && !is_background(pixel) {
            mesh += 1;
            let luma = 0.3 * f64::from(pixel[0]) + 0.59 * f64::from(pixel[1]) + 0.11 * f64::from(pixel[2]);
            if luma < 90.0 {
                dark += 1;
            }
        }
    }
    dark as f64 / mesh.max(1) as f64
}

/// The 3D view as the editor would draw it at `size`, rendered offscreen: the mesh colors,
/// or (`mct`) the Mesh Color Texture built from the same packing.
fn reference_view(file: &Path, size: (u32, u32), mct: bool) -> RgbImage {
    let mut editor = Editor::new(None, Arc::new(|| {}));
    editor.open(Source::File(file.to_owned()));
    assert!(editor.wait_for_job(Duration::from_secs(60)));
    editor.viewport.rect = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(size.0 as f32, size.1 as f32));
    editor.viewport.pixels_per_point = 1.0;
    editor.frame_all();
    let open = editor.document.open.as_ref().expect("the reference document did not open");
    let packed = open.document.pack(open.format).unwrap();
    let Gpu { ctx, renderer } = Gpu::create();
    let mesh = GpuMesh::upload(&ctx, renderer.layouts(), &packed, &MeshUploadOptions::default()).unwrap();
    let settings = editor.render_settings();
    let image = if mct {
        let texture = meshpaint_core::mct::build(&packed, 16384, u64::MAX).unwrap();
        let mct = GpuMct::upload(&ctx, renderer.layouts(), &mesh.geometry(), &texture).unwrap();
        renderer.render_image(&ctx, DrawItem::Mct(&mct), &settings, size.0, size.1).unwrap()
    } else {
        renderer.render_image(&ctx, DrawItem::MeshColors(&mesh), &settings, size.0, size.1).unwrap()
    };
    image::DynamicImage::ImageRgba8(image).to_rgb8()
}

/// Mean absolute difference per channel, and the share of pixels off by more than 24,
/// over the view without its bottom 30 rows (the hint text).
fn compare(a: &RgbImage, b: &RgbImage) -> (f64, f64) {
    assert_eq!(a.dimensions(), b.dimensions());
    let (w, h) = a.dimensions();
    let (mut sum, mut off, mut n) = (0u64, 0u64, 0u64);
    for y in 0..h.saturating_sub(30) {
        for x in 0..w {
            let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
            let d: Vec<u8> = (0..3).map(|c| p[c].abs_diff(q[c])).collect();
            sum += d.iter().map(|&v| u64::from(v)).sum::<u64>();
            if d.iter().any(|&v| v > 24) {
                off += 1;
            }
            n += 1;
        }
    }
    (sum as f64 / (3 * n) as f64, off as f64 / n as f64)
}

/// The window tests share the machine's displays and cores: one at a time.
static WINDOW_TESTS: std::sync::Mutex<()> = std::sync::Mutex::new(());

#[test]
fn the_editor_window_orbits_toggles_exports_and_survives_bad_files() {
    let _serial = WINDOW_TESTS.lock().unwrap_or_else(|e| e.into_inner());
    for tool in ["Xvfb", "xdotool", "import"] {
        require_tool(tool);
    }
    let dir = std::env::temp_dir().join(format!("meshpaint_app_window_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log_path = dir.join("app.log");
    let mut processes = Processes { children: Vec::new() };
    let display = start_xvfb(&mut processes);

    let asset = workspace_path("assets/models/Duck/Duck.glb");
    processes.children.push(start_app(&display, &dir, &log_path, &asset, &[]));
    // The app is the last child.
    macro_rules! app {
        () => {
            processes.children.last_mut().unwrap()
        };
    }

    wait_for_log(&log_path, "Opened Duck.glb", 0, Duration::from_secs(120), app!());
    focus_window(&display);
    let log = wait_for_log(&log_path, "3D view at ", 0, Duration::from_secs(60), app!());
    let rect = view_rect(&log);
    assert!(rect.2 > 400 && rect.3 > 300, "3D view too small: {rect:?}\n{log}");

    // 1. The default view: not blank, and the same image as an offscreen render.
    // Screenshots go to target/test-output (never over the committed screenshots/, unless
    // MESHPAINT_UPDATE_SCREENSHOTS=1 asks for it once the checks on them passed).
    let shots = output_dir();
    let first =
        wait_for_screen(&display, &shots.join("app_duck.png"), rect, "the Duck", &|s| view_drawn(s, rect), app!());
    let view = crop(&first, rect);
    check_view_not_blank(&view, "default view");
    let reference = reference_view(&asset, (rect.2, rect.3), false);
    let (mean, off) = compare(&view, &reference);
    assert!(
        mean < 2.0 && off < 0.02,
        "the 3D view differs from the offscreen render: mean {mean:.2}, {:.1}% off",
        off * 100.0
    );
    update_screenshot(&shots.join("app_duck.png"), "app_duck.png");

    // 1b. Mesh Color Textures (T): the window logs that it draws them, and the view must
    // equal the offscreen MCT render of the same packing. (MCT and mesh colors' trilinear are
    // within a step or two of each other by design — docs/MCT.md — so the image alone cannot
    // tell which pipeline drew it; the log line can.) Then back to mesh colors (T).
    let from = read_log(&log_path).len();
    xdotool(&display, &["key", "t"]);
    wait_for_log(&log_path, "3D view draws Mesh Color Textures", from, Duration::from_secs(120), app!());
    // The side panel may have widened since (its texts): the view's latest rectangle.
    let rect = view_rect(&read_log(&log_path));
    let mct_reference = reference_view(&asset, (rect.2, rect.3), true);
    let is_mct = |shot: &RgbImage| compare(&crop(shot, rect), &mct_reference).0 < 2.0;
    let shot = wait_for_screen(&display, &shots.join("app_duck_mct.png"), rect, "the MCT view", &is_mct, app!());
    let (mean, off) = compare(&crop(&shot, rect), &mct_reference);
    assert!(
        mean < 2.0 && off < 0.02,
        "the MCT view differs from its offscreen render: mean {mean:.2}, {:.2}% off",
        off * 100.0
    );
    let from = read_log(&log_path).len();
    xdotool(&display, &["key", "t"]);
    wait_for_log(&log_path, "3D view draws mesh colors", from, Duration::from_secs(60), app!());
    let rect = view_rect(&read_log(&log_path));
    let shot =
        wait_for_screen(&display, &dir.join("back.png"), rect, "mesh colors again", &|s| view_drawn(s, rect), app!());
    let view = crop(&shot, rect);

    // 2. Orbit with the middle button, toggle the wireframe with W.
    let (cx, cy) = (rect.0 + rect.2 / 2, rect.1 + rect.3 / 2);
    xdotool(&display, &["mousemove", "--sync", &cx.to_string(), &cy.to_string()]);
    xdotool(&display, &["mousedown", "2"]);
    // Pacing, not waiting: each step is a separate motion event for the orbit. What the test
    // waits for is the screen below.
    for step in 1..=4 {
        pause(0.3);
        xdotool(&display, &["mousemove", "--sync", &(cx + 40 * step).to_string(), &(cy + 12 * step).to_string()]);
    }
    xdotool(&display, &["mouseup", "2"]);
    xdotool(&display, &["key", "w"]);
    let before = dark_share(&view);
    let wired = |shot: &RgbImage| dark_share(&crop(shot, rect)) > before + 0.05;
    let second =
        wait_for_screen(&display, &shots.join("app_duck_orbit_wireframe.png"), rect, "the wireframe", &wired, app!());
    let orbited = crop(&second, rect);
    check_view_not_blank(&orbited, "orbited view");
    let (moved, _) = compare(&orbited, &view);
    assert!(moved > 3.0, "orbiting did not change the view (mean difference {moved:.2})");
    let (before, after) = (dark_share(&view), dark_share(&orbited));
    assert!(after > before + 0.05, "no wireframe: dark share {before:.3} → {after:.3}");
    update_screenshot(&shots.join("app_duck_orbit_wireframe.png"), "app_duck_orbit_wireframe.png");

    // 3. Export glTF through the dialog (Ctrl+E, type the path, Enter).
    let exported = dir.join("exported duck.glb");
    let from = read_log(&log_path).len();
    type_into_dialog(&display, &log_path, "ctrl+e", &exported, app!());
    wait_for_log(&log_path, "Exported", from, Duration::from_secs(120), app!());
    let bytes = std::fs::read(&exported).expect("no exported file");
    assert_eq!(&bytes[..4], b"glTF");
    assert_eq!(u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize, bytes.len());
    let scene = meshpaint_core::mesh::import::import_gltf(&exported).expect("the exported .glb does not load");
    assert_eq!(scene.instanced_triangle_count(), 4212 * 8 * 8, "R = 8: R² triangles per face");

    // 4. Open a broken file (Ctrl+O): the error shows, the Duck stays, the app runs on.
    let broken = workspace_path("tests/fixtures/invalid/gltf-validator/glb/invalid_magic.glb");
    let from = read_log(&log_path).len();
    type_into_dialog(&display, &log_path, "ctrl+o", &broken, app!());
    wait_for_log(&log_path, "Could not open", from, Duration::from_secs(60), app!());
    // The status line (bottom rows) shows the error in the error colour (red).
    let red = |shot: &RgbImage| {
        (0..shot.width())
            .flat_map(|x| (shot.height() - 22..shot.height()).map(move |y| (x, y)))
            .filter(|&(x, y)| {
                let p = shot.get_pixel(x, y);
                p[0] > 150 && p[1] < 110 && p[2] < 110
            })
            .count()
    };
    let third = wait_for_screen(&display, &dir.join("after_error.png"), rect, "the error", &|s| red(s) > 50, app!());
    assert!(app!().try_wait().unwrap().is_none(), "the app exited after a bad file");
    check_view_not_blank(&crop(&third, rect), "view after the bad file");

    // 4b. OBJ, PLY and STL open through the same dialog and show; a broken PLY keeps the last.
    let broken_ply = dir.join("broken.ply");
    std::fs::write(&broken_ply, b"ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nend_header\n1\n").unwrap();
    for (file, needle) in [
        ("assets/models/AssimpTestModels/cube_with_vertexcolors.obj", "Opened cube_with_vertexcolors.obj"),
        ("assets/models/PlyExamples/greg_turk_example2_ok_ascii.ply", "Opened greg_turk_example2_ok_ascii.ply"),
        ("assets/models/AssimpTestModels/sphereWithHole.stl", "Opened sphereWithHole.stl"),
        (broken_ply.to_str().unwrap(), "Could not open"),
    ] {
        let from = read_log(&log_path).len();
        type_into_dialog(&display, &log_path, "ctrl+o", &workspace_path(file), app!());
        wait_for_log(&log_path, needle, from, Duration::from_secs(60), app!());
        // A longer document name can widen the side panel: the view's latest rectangle, once
        // two screenshots in a row agree on a drawn view.
        let latest = || view_rect(&read_log(&log_path));
        let drawn = |shot: &RgbImage| view_drawn(shot, latest());
        let shot = wait_for_screen(&display, &dir.join("mesh_format.png"), latest(), needle, &drawn, app!());
        check_view_not_blank(&crop(&shot, latest()), needle);
    }

    // 5. Ctrl+Q quits cleanly.
    let status = quit(&display, app!());
    processes.children.pop();
    let log = read_log(&log_path);
    assert!(status.success(), "exit status {status}:\n{log}");
    assert!(!log.contains("panicked"), "{log}");
    drop(processes);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn blank_or_misplaced_views_fail_the_checks() {
    let blank = RgbImage::from_pixel(900, 700, image::Rgb(background()));
    assert!(std::panic::catch_unwind(|| check_view_not_blank(&blank, "blank")).is_err());
    let black = RgbImage::from_pixel(900, 700, image::Rgb([0, 0, 0]));
    assert!(std::panic::catch_unwind(|| check_view_not_blank(&black, "black")).is_err());
    let mut off_centre = blank.clone();
    for y in 20..260 {
        for x in 20..300 {
            off_centre.put_pixel(x, y, image::Rgb([230, 200, 20]));
        }
    }
    assert!(std::panic::catch_unwind(|| check_view_not_blank(&off_centre, "off centre")).is_err());
    let mut centred = blank.clone();
    for y in 200..500 {
        for x in 300..600 {
            centred.put_pixel(x, y, image::Rgb([230, 200, 20]));
        }
    }
    check_view_not_blank(&centred, "centred square");
}

/// Distance from `p` to the segment `a`–`b`.
fn distance_to_segment(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy).max(1e-12)).clamp(0.0, 1.0);
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

/// Every sample of `document` with its world position.
fn samples_with_positions(
    document: &meshpaint_core::io::document::Document,
) -> Vec<(meshpaint_core::colors::store::SampleRef, [f32; 4], glam::DVec3)> {
    let store = &document.store;
    let mut out = Vec::new();
    store.for_each_site(|site| {
        let corners = store.topology().face_vertices[site.face as usize];
        let mut p = glam::DVec3::ZERO;
        for (k, &v) in corners.iter().enumerate() {
            let q = document.positions[v as usize];
            p += glam::DVec3::new(f64::from(q[0]), f64::from(q[1]), f64::from(q[2])) * f64::from(site.barycentric[k]);
        }
        out.push((site.sample, store.get(site.sample).unwrap(), p));
    });
    out
}

/// A horizontal stroke `(x0, x1, y)` in screen pixels.
type Stroke = (u32, u32, u32);

/// Enters paint mode (Tab) with the cursor on the view and paints a horizontal stroke across
/// the middle of the Duck (the default brush: red, 30 px); waits until it shows. Returns it.
fn paint_a_stroke(display: &str, log_path: &Path, rect: (u32, u32, u32, u32), app: &mut Child) -> Stroke {
    let (cx, cy) = (rect.0 + rect.2 / 2, rect.1 + rect.3 / 2);
    xdotool(display, &["mousemove", "--sync", &cx.to_string(), &cy.to_string()]);
    let from = read_log(log_path).len();
    xdotool(display, &["key", "Tab"]);
    wait_for_log(log_path, "Paint mode", from, Duration::from_secs(30), app);
    let shots = output_dir();
    wait_for_screen(display, &shots.join("app_paint_mode.png"), rect, "paint mode", &|s| view_drawn(s, rect), app);

    let (x0, x1, y) = (cx - 120, cx + 120, cy + 20);
    xdotool(display, &["mousemove", "--sync", &x0.to_string(), &y.to_string()]);
    let from = read_log(log_path).len();
    xdotool(display, &["mousedown", "1"]);
    // Pacing, not waiting: each step is a separate motion event for the brush.
    for step in 1..=6 {
        let x = x0 + (x1 - x0) * step / 6;
        pause(0.3);
        xdotool(display, &["mousemove", "--sync", &x.to_string(), &y.to_string()]);
    }
    xdotool(display, &["mouseup", "1"]);
    wait_for_log(log_path, "paint stroke", from, Duration::from_secs(30), app);
    let shot_path = shots.join("app_paint.png");
    let red_near_stroke = |shot: &RgbImage| {
        crop(shot, rect)
            .enumerate_pixels()
            .filter(|&(px, py, p)| {
                let (vx, vy) = (f64::from(px + rect.0), f64::from(py + rect.1));
                distance_to_segment((vx, vy), (f64::from(x0), f64::from(y)), (f64::from(x1), f64::from(y))) < 30.0
                    && p[0] > 150
                    && p[1] < 80
                    && p[2] < 80
            })
            .count()
            > 2000
    };
    wait_for_screen(display, &shot_path, rect, "a red stroke (over 2000 red pixels near it)", &red_near_stroke, app);
    (x0, x1, y)
}

/// The samples of `painted` differ from those of `original` only under `stroke` (within the
/// brush radius, seen from the camera the editor computes for the view `rect`), towards red,
/// and at least 1000 of them.
fn assert_only_the_stroke_changed(
    original: &meshpaint_core::io::document::Document,
    painted: &meshpaint_core::io::document::Document,
    asset: &Path,
    rect: (u32, u32, u32, u32),
    (x0, x1, y): Stroke,
) {
    let before = samples_with_positions(original);
    let after = samples_with_positions(painted);
    assert_eq!(before.len(), after.len(), "the sample count changed");
    // The app's camera: the same editor state the app computed at this view size.
    let mut editor = Editor::new(None, Arc::new(|| {}));
    editor.open(Source::File(asset.to_owned()));
    assert!(editor.wait_for_job(Duration::from_secs(60)));
    editor.viewport.rect = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(rect.2 as f32, rect.3 as f32));
    editor.viewport.pixels_per_point = 1.0;
    editor.frame_all();
    let camera = editor.camera;
    let a = (f64::from(x0 - rect.0), f64::from(y - rect.1));
    let b = (f64::from(x1 - rect.0), f64::from(y - rect.1));
    let radius_px = 30.0;
    let mut changed = 0;
    let mut worst: f64 = 0.0;
    for ((sample, old, position), (sample_after, new, _)) in before.iter().zip(&after) {
        assert_eq!(sample, sample_after);
        if old == new {
            continue;
        }
        changed += 1;
        let (px, py) = camera.project(*position, rect.2, rect.3).expect("a changed sample behind the camera");
        let d = distance_to_segment((px, py), a, b);
        worst = worst.max(d);
        assert!(
            d <= radius_px * 1.25 + 4.0,
            "sample {sample:?} changed at ({px:.1}, {py:.1}), {d:.1} px from the stroke (radius {radius_px} px)"
        );
        // The default brush paints red.
        assert!(new[0] > new[1] && new[0] > new[2], "sample {sample:?} changed to {new:?}, not towards red");
    }
    eprintln!("{changed} samples changed, farthest {worst:.1} px from the stroke");
    assert!(changed >= 1000, "only {changed} samples changed");
}

/// `document` after a save in `format` (as the editor's save quantises it).
fn quantised(
    document: &meshpaint_core::io::document::Document,
    format: meshpaint_core::colors::format::ColorFormat,
) -> meshpaint_core::io::document::Document {
    meshpaint_core::io::document::Document::from_packed(&document.pack(format).unwrap()).unwrap()
}

#[test]
fn paint_mode_stroke_lands_under_the_cursor_and_is_saved() {
    let _serial = WINDOW_TESTS.lock().unwrap_or_else(|e| e.into_inner());
    for tool in ["Xvfb", "xdotool", "import"] {
        require_tool(tool);
    }
    let dir = std::env::temp_dir().join(format!("meshpaint_app_paint_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log_path = dir.join("app.log");
    let mut processes = Processes { children: Vec::new() };
    let display = start_xvfb(&mut processes);
    let asset = workspace_path("assets/models/Duck/Duck.glb");
    processes.children.push(start_app(&display, &dir, &log_path, &asset, &[]));
    macro_rules! app {
        () => {
            processes.children.last_mut().unwrap()
        };
    }
    wait_for_log(&log_path, "Opened Duck.glb", 0, Duration::from_secs(120), app!());
    focus_window(&display);
    let rect = view_rect(&wait_for_log(&log_path, "3D view at ", 0, Duration::from_secs(60), app!()));
    let stroke = paint_a_stroke(&display, &log_path, rect, app!());
    update_screenshot(&output_dir().join("app_paint.png"), "app_paint.png");

    // Ctrl+Q with the stroke unsaved asks first (the modal prompt dims the view); Esc
    // cancels it and the editor runs on with the stroke.
    let brightness = |shot: &RgbImage| {
        let view = crop(shot, rect);
        view.pixels().map(|p| u64::from(p[0]) + u64::from(p[1]) + u64::from(p[2])).sum::<u64>() as f64
            / (3 * view.width() * view.height()) as f64
    };
    let before = brightness(&screenshot(&display, &dir.join("before_quit.png")));
    let from = read_log(&log_path).len();
    xdotool(&display, &["key", "ctrl+q"]);
    wait_for_log(&log_path, "Unsaved changes: asking before quitting", from, Duration::from_secs(30), app!());
    let dimmed = |shot: &RgbImage| brightness(shot) < before - 10.0;
    wait_for_screen(&display, &output_dir().join("app_unsaved_prompt.png"), rect, "the prompt", &dimmed, app!());
    xdotool(&display, &["key", "Escape"]);
    let clear = |shot: &RgbImage| (brightness(shot) - before).abs() < 2.0;
    wait_for_screen(&display, &dir.join("prompt_cancelled.png"), rect, "the view without the prompt", &clear, app!());
    assert!(app!().try_wait().unwrap().is_none(), "the editor quit although the prompt was cancelled");

    // Tab leaves (repack), Ctrl+S saves through the dialog.
    let from = read_log(&log_path).len();
    xdotool(&display, &["key", "Tab"]);
    wait_for_log(&log_path, "Repacked", from, Duration::from_secs(60), app!());
    let saved = dir.join("painted duck.mpk");
    let from = read_log(&log_path).len();
    type_into_dialog(&display, &log_path, "ctrl+s", &saved, app!());
    wait_for_log(&log_path, "Saved", from, Duration::from_secs(120), app!());
    quit(&display, app!());
    processes.children.pop();
    let log = read_log(&log_path);
    assert!(!log.contains("panicked"), "{log}");

    // The saved colours differ from the original only under the stroke.
    let r8 = meshpaint_core::colors::layout::Resolution::new(8).unwrap();
    let painted = meshpaint_core::io::document::Document::open(&saved, r8).expect("the saved file does not open");
    let format = match painted.source {
        meshpaint_core::io::document::SourceKind::Packed(format) => format,
        other => panic!("the saved file is not packed: {other:?}"),
    };
    // Quantise the original exactly as the save did.
    let original = quantised(&meshpaint_core::io::document::Document::open(&asset, r8).unwrap(), format);
    assert_only_the_stroke_changed(&original, &painted, &asset, rect, stroke);
    drop(processes);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every sample's colour, in `for_each_site` order.
fn colors(document: &meshpaint_core::io::document::Document) -> Vec<[f32; 4]> {
    let mut out = Vec::new();
    document.store.for_each_site(|site| out.push(document.store.get(site.sample).unwrap()));
    out
}

#[test]
fn a_killed_editor_offers_its_autosave_and_restores_what_was_painted() {
    let _serial = WINDOW_TESTS.lock().unwrap_or_else(|e| e.into_inner());
    for tool in ["Xvfb", "xdotool", "import"] {
        require_tool(tool);
    }
    let dir = std::env::temp_dir().join(format!("meshpaint_app_recovery_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let mut processes = Processes { children: Vec::new() };
    let display = start_xvfb(&mut processes);
    let asset = workspace_path("assets/models/Duck/Duck.glb");
    // Autosave every second (the default is 60 s).
    let env = [("MESHPAINT_AUTOSAVE_SECONDS", "1")];
    let first_log = dir.join("first.log");
    processes.children.push(start_app(&display, &dir, &first_log, &asset, &env));
    macro_rules! app {
        () => {
            processes.children.last_mut().unwrap()
        };
    }
    wait_for_log(&first_log, "Opened Duck.glb", 0, Duration::from_secs(120), app!());
    focus_window(&display);
    let rect = view_rect(&wait_for_log(&first_log, "3D view at ", 0, Duration::from_secs(60), app!()));
    let stroke = paint_a_stroke(&display, &first_log, rect, app!());

    // The first autosave after the stroke (it may already be there), then kill -9.
    let from = read_log(&first_log).find("paint stroke").unwrap();
    let log = wait_for_log(&first_log, "Autosaved ", from, Duration::from_secs(60), app!());
    let line = log[from..].lines().find(|l| l.contains("Autosaved ")).unwrap();
    let recovery = line[line.find("Autosaved ").unwrap() + "Autosaved ".len()..].split(" (").next().unwrap();
    let recovery = std::path::PathBuf::from(recovery);
    let autosaved = std::fs::read(&recovery).expect("no recovery file");
    sigkill(app!());
    processes.children.pop();

    // What the autosave holds: the painted Duck (an independent check of the stroke).
    let r8 = meshpaint_core::colors::layout::Resolution::new(8).unwrap();
    let autosave = meshpaint_core::io::document::Document::from_packed(
        &meshpaint_core::packing::file::from_bytes(&autosaved).unwrap(),
    )
    .unwrap();
    let original = meshpaint_core::io::document::Document::open(&asset, r8).unwrap();
    assert_only_the_stroke_changed(&original, &autosave, &asset, rect, stroke);

    // Restart: the recovery offer appears; Restore.
    let second_log = dir.join("second.log");
    processes.children.push(start_app(&display, &dir, &second_log, &asset, &env));
    wait_for_log(&second_log, "Opened Duck.glb", 0, Duration::from_secs(120), app!());
    focus_window(&display);
    let offered = "Restore button at ";
    let mut restored = false;
    for _attempt in 0..5 {
        let log = wait_for_log(&second_log, offered, 0, Duration::from_secs(60), app!());
        let line = log.lines().rev().find(|l| l.contains(offered)).unwrap();
        let at = &line[line.find(offered).unwrap() + offered.len()..];
        let mut numbers = at.split(|c: char| !c.is_ascii_digit()).filter(|n| !n.is_empty());
        let (x, y) = (numbers.next().unwrap(), numbers.next().unwrap());
        let from = read_log(&second_log).len();
        xdotool(&display, &["mousemove", "--sync", x, y, "click", "1"]);
        // The restored document opens (state), or the click came before the button was
        // there: look again at where it is now.
        let started = Instant::now();
        while started.elapsed() < Duration::from_secs(10) {
            if read_log(&second_log).get(from..).is_some_and(|tail| tail.contains("Opened ")) {
                restored = true;
                break;
            }
            std::thread::sleep(Duration::from_millis(100));
        }
        if restored {
            break;
        }
    }
    assert!(restored, "Restore did not open the recovery file:\n{}", read_log(&second_log));

    // Save the restored document; the recovery file goes away with the save.
    let saved = dir.join("recovered.mpk");
    let from = read_log(&second_log).len();
    type_into_dialog(&display, &second_log, "ctrl+s", &saved, app!());
    wait_for_log(&second_log, "Saved", from, Duration::from_secs(120), app!());
    let status = quit(&display, app!());
    processes.children.pop();
    let log = read_log(&second_log);
    assert!(status.success() && !log.contains("panicked"), "{status}:\n{log}");
    assert!(!recovery.exists(), "the recovery file {} outlived the save", recovery.display());

    // The saved file holds exactly the autosaved samples (quantised as the save does).
    let recovered = meshpaint_core::io::document::Document::open(&saved, r8).unwrap();
    let format = match recovered.source {
        meshpaint_core::io::document::SourceKind::Packed(format) => format,
        other => panic!("the saved file is not packed: {other:?}"),
    };
    let expected = colors(&quantised(&autosave, format));
    let found = colors(&recovered);
    assert_eq!(expected.len(), found.len());
    let differ = expected.iter().zip(&found).filter(|(a, b)| a != b).count();
    assert_eq!(differ, 0, "{differ} of {} recovered samples differ from the autosave", found.len());
    drop(processes);
    let _ = std::fs::remove_dir_all(&dir);
}

/// SIGKILL (std's `Child::kill`), then reap.
fn sigkill(app: &mut Child) {
    app.kill().unwrap();
    let status = app.wait().unwrap();
    use std::os::unix::process::ExitStatusExt;
    assert_eq!(status.signal(), Some(9), "the app was not killed by SIGKILL: {status}");
}

/// The number of UI passes the app reports in `MESHPAINT_FRAME_COUNT_FILE` (0 before the first).
fn frames_run(path: &Path) -> u64 {
    std::fs::read_to_string(path).ok().and_then(|text| text.trim().parse().ok()).unwrap_or(0)
}

#[test]
fn an_idle_editor_renders_no_frames() {
    let _serial = WINDOW_TESTS.lock().unwrap_or_else(|e| e.into_inner());
    for tool in ["Xvfb", "xdotool"] {
        require_tool(tool);
    }
    let dir = std::env::temp_dir().join(format!("meshpaint_app_idle_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let log_path = dir.join("app.log");
    let count_path = dir.join("frames");
    let mut processes = Processes { children: Vec::new() };
    let display = start_xvfb(&mut processes);
    let asset = workspace_path("assets/models/Duck/Duck.glb");
    let count_env = count_path.to_string_lossy().into_owned();
    processes.children.push(start_app(
        &display,
        &dir,
        &log_path,
        &asset,
        &[("MESHPAINT_FRAME_COUNT_FILE", &count_env), ("MESHPAINT_AUTOSAVE_SECONDS", "3600")],
    ));
    let app = processes.children.last_mut().unwrap();
    wait_for_log(&log_path, "Opened Duck.glb", 0, Duration::from_secs(120), app);
    let log = wait_for_log(&log_path, "3D view at ", 0, Duration::from_secs(60), app);
    let rect = view_rect(&log);
    // The pointer rests over the 3D view, as an artist's would.
    let (x, y) = (rect.0 + rect.2 / 2, rect.1 + rect.3 / 2);
    xdotool(&display, &["mousemove", &x.to_string(), &y.to_string()]);
    assert!(frames_run(&count_path) > 0, "the app reported no frame at all");
    // At rest the count must stop: find a 2 s window with at most one pass (a pending
    // hover or fade may take one) within 60 s. A continuous redraw (tens of passes per
    // window) or any timer below 2 s never finds one, however slow the machine.
    let started = Instant::now();
    let mut windows = Vec::new();
    loop {
        let before = frames_run(&count_path);
        std::thread::sleep(Duration::from_secs(2));
        let after = frames_run(&count_path);
        windows.push(after - before);
        if after - before <= 1 {
            break;
        }
        if let Ok(Some(status)) = app.try_wait() {
            panic!("the app exited ({status}):\n{}", read_log(&log_path));
        }
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "the idle editor kept running UI passes: {windows:?} per 2 s window"
        );
    }
    // And it wakes up for input: a key press is a new frame.
    let before = frames_run(&count_path);
    focus_window(&display);
    xdotool(&display, &["mousemove", &(x + 20).to_string(), &(y + 10).to_string()]);
    let woke = Instant::now();
    while frames_run(&count_path) == before {
        assert!(woke.elapsed() < Duration::from_secs(30), "no frame after the pointer moved");
        std::thread::sleep(Duration::from_millis(50));
    }
    let status = quit(&display, app);
    assert!(status.success(), "{status}:\n{}", read_log(&log_path));
}
