//! End to end: the real `whitted debug` in a tmux terminal, driven by keys and read back as
//! screen text, the way a user would see it. Each test runs its own tmux server (a private
//! socket), so tests never touch a user's tmux or each other.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

/// A tmux server with one 120x40 session, killed when dropped.
struct Tmux {
    socket: String,
    session: String,
}

/// How long any one expected screen may take to appear (a cold debug build on a busy CI
/// machine is slow; a healthy run waits well under a second for each).
const PATIENCE: Duration = Duration::from_secs(60);

impl Tmux {
    /// Starts `command` (run by `sh -c` in `dir`) in a detached session of the given size.
    /// When the command ends, the shell prints a marker and stays, so the screen can be read.
    fn start(name: &str, dir: &Path, command: &str, width: u16, height: u16) -> Tmux {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let unique = format!("whitted-{name}-{}-{nanos}", std::process::id());
        let tmux = Tmux {
            socket: unique.clone(),
            session: unique,
        };
        let script = format!("{command}; echo \"debugger exited with $?\"; sleep 600");
        let output = tmux.run(&[
            "new-session",
            "-d",
            "-s",
            &tmux.session,
            "-x",
            &width.to_string(),
            "-y",
            &height.to_string(),
            "-c",
            &dir.display().to_string(),
            "sh",
            "-c",
            &script,
        ]);
        assert!(
            output.status.success(),
            "cannot start tmux (is it installed? .ci/run installs it): {}",
            String::from_utf8_lossy(&output.stderr)
        );
        tmux
    }

    fn run(&self, args: &[&str]) -> Output {
        Command::new("tmux")
            .arg("-L")
            .arg(&self.socket)
            .args(args)
            .env_remove("TMUX")
            .output()
            .expect("tmux runs (it is installed by .ci/run)")
    }

    fn keys(&self, keys: &[&str]) {
        for key in keys {
            let output = self.run(&["send-keys", "-t", &self.session, key]);
            assert!(output.status.success(), "send-keys {key}");
        }
    }

    /// Types `text` as it is (no key names).
    fn type_text(&self, text: &str) {
        let output = self.run(&["send-keys", "-t", &self.session, "-l", text]);
        assert!(output.status.success(), "send-keys -l {text}");
    }

    fn screen(&self) -> String {
        let output = self.run(&["capture-pane", "-p", "-t", &self.session]);
        String::from_utf8_lossy(&output.stdout).into_owned()
    }

    /// A tmux format variable of the pane, e.g. `alternate_on`.
    fn pane_flag(&self, name: &str) -> String {
        let format = format!("#{{{name}}}");
        let output = self.run(&["display-message", "-p", "-t", &self.session, &format]);
        String::from_utf8_lossy(&output.stdout).trim().to_string()
    }

    /// Polls the screen until `ready` holds on two captures in a row that are the same;
    /// fails with the last screen after [`PATIENCE`]. One capture is not enough: tmux can
    /// capture a frame half written (CI caught a tree title new and its rows still old).
    fn wait_for(&self, what: &str, ready: impl Fn(&str) -> bool) -> String {
        let started = Instant::now();
        let mut previous: Option<String> = None;
        loop {
            let screen = self.screen();
            if ready(&screen) {
                if previous.as_deref() == Some(screen.as_str()) {
                    return screen;
                }
                previous = Some(screen.clone());
            } else {
                previous = None;
            }
            assert!(
                started.elapsed() < PATIENCE,
                "waited {PATIENCE:?} for {what}; the screen shows:\n{screen}"
            );
            std::thread::sleep(Duration::from_millis(40));
        }
    }

    /// Presses Down in the tree until the inspector shows a ray of `kind` (each press waits
    /// for the inspector to change, so no fixed delays).
    fn select_in_tree(&self, kind: &str) -> String {
        let wanted = format!("Inspector · {kind} ray");
        for _ in 0..30 {
            let before = inspector_title(&self.screen());
            if before.contains(&wanted) {
                break;
            }
            self.keys(&["Down"]);
            self.wait_for("the selection to move", |s| inspector_title(s) != before);
        }
        self.wait_for(&wanted, |s| s.contains(&wanted))
    }
}

/// The inspector pane's title (it names the selected ray).
fn inspector_title(screen: &str) -> String {
    let line = line_with(screen, "Inspector");
    line.find("Inspector")
        .map(|start| line[start..].chars().take(40).collect())
        .unwrap_or_default()
}

impl Drop for Tmux {
    fn drop(&mut self) {
        let _ = self.run(&["kill-server"]);
    }
}

fn whitted() -> &'static str {
    env!("CARGO_BIN_EXE_whitted")
}

fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The line of the screen that contains `needle`.
fn line_with<'a>(screen: &'a str, needle: &str) -> &'a str {
    screen.lines().find(|l| l.contains(needle)).unwrap_or("")
}

#[test]
fn pick_the_glass_sphere_walk_to_the_transmitted_ray_export_and_quit() {
    // The scene in one folder, the debugger started in another: `e` writes beside the scene.
    let out = tempfile::tempdir().expect("a temporary directory");
    let scene_dir = tempfile::tempdir().expect("a temporary directory");
    let scene = scene_dir.path().join("whitted.scene");
    std::fs::copy(repository().join("scenes/whitted.scene"), &scene).expect("a scene copy");
    let command = format!("'{}' debug '{}'", whitted(), scene.display());
    let tmux = Tmux::start("pick", out.path(), &command, 120, 40);

    tmux.wait_for("the finished image", |s| s.contains("rendered in"));
    assert_eq!(
        tmux.pane_flag("alternate_on"),
        "1",
        "the debugger uses the alternate screen"
    );
    assert!(
        tmux.screen().contains("(320, 240)"),
        "the cursor starts in the middle"
    );

    // The glass sphere is right of centre (+x is on the image's left): 80 px right, 30 down.
    // An arrow moves one cell (11 pixels at this size), Shift+arrow (HJKL) one pixel.
    tmux.keys(&["Right"; 7]);
    tmux.wait_for("seven cells right", |s| s.contains("(397, 240)"));
    tmux.keys(&["L", "L", "L", "Down", "Down", "Down", "K", "K", "K"]);
    tmux.wait_for("the cursor on (400, 270)", |s| s.contains("(400, 270)"));
    tmux.keys(&["Enter"]);
    let screen = tmux.wait_for("the ray tree of the pixel", |s| {
        s.contains("Ray tree of (400, 270)")
    });
    assert!(
        line_with(&screen, "▼ camera").contains("glass sphere"),
        "the camera ray hits the glass sphere:\n{screen}"
    );
    assert!(
        screen.contains("Inspector · camera ray, depth 0"),
        "{screen}"
    );
    assert!(screen.contains("Source · "), "{screen}");
    assert!(
        line_with(&screen, "Source · ").contains("whitted.scene:20:1"),
        "{screen}"
    );

    // Into the tree, then down until the transmitted ray is selected.
    tmux.keys(&["Tab"]);
    let screen = tmux.select_in_tree("transmitted");
    assert!(
        screen.contains("Inspector · transmitted ray, depth 1"),
        "{screen}"
    );
    assert!(
        screen.contains("1.000 → 1.500"),
        "refraction into glass:\n{screen}"
    );
    assert!(screen.contains("entering the solid"), "{screen}");
    assert!(
        screen.contains("back face (inside)"),
        "it hits the far side:\n{screen}"
    );
    assert!(
        line_with(&screen, "transmitted d1").contains("glass sphere (ins"),
        "{screen}"
    );

    // Export the tree as JSON beside the scene (not into the working directory), and say
    // the whole path.
    tmux.keys(&["e"]);
    let screen = tmux.wait_for("the export message", |s| {
        s.contains("(the ray tree of (400, 270))")
    });
    let exported = scene_dir.path().join("whitted-400-270.ray-tree.json");
    assert!(
        screen.contains(&exported.display().to_string()),
        "the status line says where:\n{screen}"
    );
    assert!(!out.path().join("whitted-400-270.ray-tree.json").exists());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&exported).expect("the export file exists"))
            .expect("the export is JSON");
    assert_eq!(json["pixel"], serde_json::json!([400, 270]));
    assert_eq!(json["root"]["kind"], "camera");

    // Help lists the keys; any key closes it; q quits and gives the terminal back.
    tmux.keys(&["?"]);
    tmux.wait_for("the help", |s| s.contains("Keys · any key closes"));
    tmux.keys(&["x"]);
    tmux.wait_for("the help to close", |s| {
        !s.contains("Keys · any key closes")
    });
    tmux.keys(&["q"]);
    let screen = tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
    assert!(
        !screen.contains("Ray tree"),
        "the main screen is back:\n{screen}"
    );
    assert_eq!(
        tmux.pane_flag("alternate_on"),
        "0",
        "the alternate screen was left"
    );
    assert_eq!(
        tmux.pane_flag("mouse_any_flag"),
        "0",
        "mouse capture is off"
    );
    assert_eq!(
        tmux.pane_flag("cursor_flag"),
        "1",
        "the cursor is shown again"
    );
}

#[test]
fn resizing_to_a_tiny_terminal_says_so_and_back_redraws() {
    let scene = repository().join("scenes/whitted.scene");
    let command = format!(
        "'{}' debug '{}' --pixel 400,270",
        whitted(),
        scene.display()
    );
    let tmux = Tmux::start("resize", &repository(), &command, 80, 24);
    // At 80 columns the tree's title leaves out the pixel (the status line has it).
    let screen = tmux.wait_for("the tree of --pixel", |s| {
        s.contains("Ray tree · 9 of 13 rays") && s.contains("rendered in")
    });
    assert!(screen.contains("Inspector · camera ray"), "{screen}");
    tmux.run(&["resize-window", "-t", &tmux.session, "-x", "40", "-y", "10"]);
    tmux.wait_for("the too-small message", |s| {
        s.contains("Terminal too small")
    });
    tmux.run(&[
        "resize-window",
        "-t",
        &tmux.session,
        "-x",
        "120",
        "-y",
        "40",
    ]);
    tmux.wait_for("the full layout again", |s| {
        s.contains("Ray tree of (400, 270)") && !s.contains("Terminal too small")
    });
    // Esc never quits (it leaves modes; q quits).
    tmux.keys(&["Escape"]);
    tmux.wait_for("Esc's hint", |s| {
        s.contains("Esc closes and leaves modes; q quits")
    });
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after q", |s| {
        s.contains("debugger exited with 0")
    });
    assert_eq!(tmux.pane_flag("alternate_on"), "0");
}

#[test]
fn light_rays_collapse_stepping_reaches_the_pixel_and_the_explanation_jumps_at_80x24() {
    let scene = repository().join("scenes/whitted.scene");
    let command = format!(
        "'{}' debug '{}' --pixel 400,270",
        whitted(),
        scene.display()
    );
    let tmux = Tmux::start("follow", &repository(), &command, 80, 24);
    tmux.wait_for("the collapsed tree", |s| {
        s.contains("9 of 13 rays, a: all") && s.contains("rendered in")
    });
    tmux.keys(&["a"]);
    tmux.wait_for("every ray", |s| s.contains("13 rays, a: collapse"));
    tmux.keys(&["a"]);
    tmux.wait_for("the light rays collapsed again", |s| {
        s.contains("9 of 13 rays")
    });
    // Stepping through all 13 rays in trace order ends at the pixel's colour (the status
    // line's numbers for the cursor pixel).
    tmux.keys(&["]"]);
    tmux.wait_for("the first step", |s| s.contains("step 2/13"));
    for _ in 0..11 {
        tmux.keys(&["]"]);
    }
    let screen = tmux.wait_for("the last step", |s| s.contains("step 13/13"));
    assert!(
        line_with(&screen, "step 13/13").contains("0.189 0.292 0.693"),
        "{screen}"
    );
    assert!(
        line_with(&screen, "rendered in").contains("0.189 0.292 0.693"),
        "{screen}"
    );
    tmux.keys(&["["]);
    tmux.wait_for("a step back", |s| s.contains("step 12/13"));
    tmux.keys(&["{"]);
    tmux.wait_for("the previous event", |s| s.contains("in trace order"));

    // The explanation in the inspector's place; Enter on the second contribution selects
    // its ray, a light's term its shadow ray.
    tmux.keys(&["x"]);
    tmux.wait_for("the explanation", |s| {
        s.contains("Explanation · Enter: go to") && s.contains("Findings")
    });
    // x gave the explanation the keyboard.
    tmux.keys(&["Down", "Down", "Enter"]);
    let screen = tmux.wait_for("the ray of the third contribution", |s| {
        line_with(s, "▸").contains("7.8% ██ diffuse from sun")
    });
    assert!(screen.contains("Ray tree"), "{screen}");
    tmux.keys(&["x"]);
    let screen = tmux.wait_for("the inspector again", |s| {
        s.contains("Inspector · shadow ray")
    });
    // At 80 columns the unfocused inspector is narrow: its title is cut after "depth".
    assert!(screen.contains("Inspector · shadow ray, depth"), "{screen}");
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
}

#[test]
fn stepping_through_the_glass_cube_stops_at_total_internal_reflection() {
    let scene = repository().join("scenes/tir.scene");
    let command = format!(
        "'{}' debug '{}' --pixel 240,170",
        whitted(),
        scene.display()
    );
    let tmux = Tmux::start("tir", &repository(), &command, 120, 40);
    tmux.wait_for("the tree of the cube", |s| {
        s.contains("Ray tree of (240, 170)") && s.contains("rendered in")
    });
    // Every ray in trace order: the running colour, absorption in the glass included, ends
    // at the pixel's.
    for _ in 0..15 {
        tmux.keys(&["]"]);
    }
    let screen = tmux.wait_for("the last ray", |s| s.contains("step 16/16"));
    let pixel = line_with(&screen, "rendered in");
    let running = line_with(&screen, "step 16/16");
    let numbers = |line: &str| {
        let after = line.split("██").nth(1).unwrap_or("").trim().to_string();
        after
            .split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    };
    let status = pixel
        .split('│')
        .find(|part| part.contains("(240, 170)"))
        .unwrap_or("");
    assert_eq!(numbers(running).split(' ').count(), 3, "{screen}");
    assert_eq!(numbers(running), numbers(status), "{screen}");
    for _ in 0..4 {
        tmux.keys(&["{"]);
    }
    tmux.wait_for("a total internal reflection", |s| {
        s.contains("total internal reflection: reflected ray")
    });
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
}

#[test]
fn editing_the_scene_reloads_it_and_errors_keep_the_last_good_image() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let scene = dir.path().join("scene.scene");
    let good = std::fs::read_to_string(repository().join("scenes/whitted.scene"))
        .expect("the scene is readable");
    std::fs::write(&scene, &good).expect("writable");
    let command = format!("'{}' debug scene.scene --pixel 400,270", whitted());
    let tmux = Tmux::start("reload", dir.path(), &command, 120, 40);
    tmux.wait_for("the first image", |s| s.contains("rendered in"));

    let broken = good.replace("radius 1 material glass", "radius material glass");
    assert_ne!(broken, good, "the test breaks the glass sphere's radius");
    std::fs::write(&scene, &broken).expect("writable");
    let screen = tmux.wait_for("the scene's errors", |s| {
        s.contains("last good image shown")
    });
    assert!(screen.contains("error:"), "{screen}");
    assert!(
        screen.contains("scene.scene:"),
        "the error says where:\n{screen}"
    );
    assert!(
        screen.contains("Ray tree of (400, 270)"),
        "the tree stays:\n{screen}"
    );

    std::fs::write(&scene, good.replace("ior 1.5", "ior 1.2")).expect("writable");
    tmux.wait_for("the fixed scene", |s| {
        s.contains("reloaded scene.scene") && !s.contains("last good image shown")
    });
    // The re-traced tree shows the new index of refraction.
    tmux.keys(&["Tab"]);
    let screen = tmux.select_in_tree("transmitted");
    assert!(screen.contains("1.000 → 1.200"), "{screen}");
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
}

#[test]
fn a_signal_from_outside_gives_the_terminal_back() {
    let scene = repository().join("scenes/whitted.scene");
    for (signal, code) in [("TERM", 143), ("HUP", 129), ("QUIT", 131), ("INT", 130)] {
        let dir = tempfile::tempdir().expect("a temporary directory");
        // The inner shell writes its process id, then becomes the debugger.
        let command = format!(
            "sh -c 'echo $$ > whitted.pid; exec \"{}\" debug \"{}\"'",
            whitted(),
            scene.display()
        );
        let tmux = Tmux::start(&format!("signal-{signal}"), dir.path(), &command, 120, 40);
        tmux.wait_for("the finished image", |s| s.contains("rendered in"));
        assert_eq!(tmux.pane_flag("alternate_on"), "1");
        assert_eq!(tmux.pane_flag("mouse_any_flag"), "1", "mouse capture is on");
        let pid = std::fs::read_to_string(dir.path().join("whitted.pid")).expect("the pid file");
        let killed = Command::new("kill")
            .arg(format!("-{signal}"))
            .arg(pid.trim())
            .status()
            .expect("kill runs");
        assert!(killed.success());
        let exited = format!("debugger exited with {code}");
        tmux.wait_for(&exited, |s| s.contains(&exited));
        assert_eq!(
            tmux.pane_flag("alternate_on"),
            "0",
            "SIG{signal}: the alternate screen was left"
        );
        assert_eq!(
            tmux.pane_flag("mouse_any_flag"),
            "0",
            "SIG{signal}: mouse capture is off"
        );
        assert_eq!(
            tmux.pane_flag("cursor_flag"),
            "1",
            "SIG{signal}: the cursor is shown again"
        );
    }
}

/// A MIT 6.837 scene in the debugger: the picked pixel's tree and the source pane point at
/// the `.txt` file's lines (the object hit and, with `m`, its material).
#[test]
fn a_course_scene_shows_its_txt_lines() {
    // Run from the scene's folder, so that the pane titles show the whole (short) path.
    let command = format!(
        "'{}' debug spheres-orthographic.txt --pixel 133,317",
        whitted()
    );
    let folder = repository().join("scenes/mit6837");
    let tmux = Tmux::start("course", &folder, &command, 120, 40);
    // Waits for the whole screen: under load tmux can be read between the title and the
    // rows of a pane being drawn, and a half-drawn source pane is not a failure.
    tmux.wait_for(
        "the pixel's tree with the sphere, and the sphere's line in the source pane",
        |s| {
            s.contains("Ray tree of (133, 317)")
                && line_with(s, "camera      d0").contains("sphere #0")
                && line_with(s, "Source · ").contains("spheres-orthographic.txt:31:5")
                && line_with(s, "31 │").contains("Sphere {")
        },
    );
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
}

/// The left pane (the image or the 3D view) of a 120-column screen: its first 60 characters
/// of every line.
fn left_pane(screen: &str) -> String {
    screen
        .lines()
        .map(|line| line.chars().take(60).collect::<String>() + "\n")
        .collect()
}

/// Whether the 3D view is fully drawn: its title, its whole legend on the bottom border
/// (written after the rows above it), and no backdrop render under way.
fn ray_view_done(screen: &str) -> bool {
    screen.contains("3D rays of (400, 270)")
        && line_with(screen, "━cam").contains("━sel")
        && !screen.contains("rendering the view")
}

/// Waits for `ready`, then until the screen stays the same for a moment: keys sent in a
/// burst each redraw the view, and the last of them is wanted.
fn wait_settled(tmux: &Tmux, what: &str, ready: impl Fn(&str) -> bool) -> String {
    loop {
        let screen = tmux.wait_for(what, &ready);
        std::thread::sleep(Duration::from_millis(300));
        if tmux.screen() == screen {
            return screen;
        }
    }
}

fn braille_count(text: &str) -> usize {
    text.chars()
        .filter(|c| ('\u{2801}'..='\u{28ff}').contains(c))
        .count()
}

#[test]
fn the_3d_view_shows_the_glass_pixels_rays_from_an_orbited_camera() {
    let scene = repository().join("scenes/whitted.scene");
    let command = format!(
        "COLORTERM=truecolor '{}' debug '{}' --pixel 400,270",
        whitted(),
        scene.display()
    );
    let tmux = Tmux::start("rays3d", &repository(), &command, 120, 40);
    tmux.wait_for("the tree of the glass pixel", |s| {
        s.contains("Ray tree of (400, 270)") && s.contains("rendered in")
    });
    tmux.keys(&["v"]);
    let home = wait_settled(&tmux, "the 3D view from the scene's camera", ray_view_done);
    assert!(!home.contains("Image 640×480"), "{home}");
    let legend = line_with(&home, "━cam");
    for name in ["refl", "trans", "shadow", "blocked", "sel"] {
        assert!(
            legend.contains(&format!("━{name}")),
            "legend: {legend}\n{home}"
        );
    }
    assert!(
        line_with(&home, "3D rays").contains("orbit"),
        "the title says the keys:\n{home}"
    );

    // Orbit 60° to the right and 15° up: the rays are seen from the side.
    tmux.keys(&["Right"; 12]);
    tmux.keys(&["Up"; 3]);
    let orbited = wait_settled(&tmux, "the orbited view", |s| {
        left_pane(s) != left_pane(&home) && ray_view_done(s)
    });
    let drawn = braille_count(&left_pane(&orbited));
    assert!(drawn > 30, "{drawn} braille cells:\n{orbited}");
    let colored = tmux.run(&["capture-pane", "-e", "-p", "-t", &tmux.session]);
    let colored = String::from_utf8_lossy(&colored.stdout);
    for (name, rgb) in [
        ("selected camera", "255;0;255"),
        ("reflected", "0;230;255"),
        ("transmitted", "255;170;0"),
        ("lit shadow", "40;255;40"),
        ("blocked shadow", "255;40;40"),
    ] {
        assert!(
            colored.contains(&format!("38;2;{rgb}m")),
            "no {name} ray in its colour:\n{orbited}"
        );
    }

    // A drag with the left button orbits too (SGR mouse reports, as a terminal sends them).
    let press = |kind: u8, column: u16, release: bool| {
        let end = if release { 'm' } else { 'M' };
        let report = format!("\x1b[<{kind};{column};10{end}");
        tmux.run(&["send-keys", "-t", &tmux.session, "-l", &report]);
    };
    press(0, 20, false);
    for column in 21..=30 {
        press(32, column, false);
    }
    press(0, 30, true);
    wait_settled(&tmux, "the dragged view", |s| {
        left_pane(s) != left_pane(&orbited) && ray_view_done(s)
    });

    // 0 puts the camera back: the very frame the view opened with.
    tmux.keys(&["0"]);
    tmux.wait_for("the scene's camera again", |s| {
        left_pane(s) == left_pane(&home)
    });
    tmux.keys(&["v"]);
    tmux.wait_for("the image again", |s| s.contains("Image 640×480"));
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
}

/// Issue 13's "done when": a new user at 80x24 picks the glass sphere of
/// scenes/whitted.scene, finds its transmitted ray, reads its numbers and sees its source
/// line without resizing, with keys only.
#[test]
fn a_new_user_at_80x24_finds_the_glass_sphere_s_transmitted_ray_and_reads_it() {
    let command = format!("'{}' debug scenes/whitted.scene", whitted());
    let tmux = Tmux::start("small", &repository(), &command, 80, 24);
    tmux.wait_for("the finished image", |s| s.contains("rendered in"));

    // At 80x24 the image pane shows 17 pixels a cell: five cells right and two down pass
    // the sphere's pixel (400, 270) by a little; single pixels (Shift: HJKL) come back.
    tmux.keys(&["Right"; 5]);
    tmux.keys(&["Down"; 2]);
    tmux.wait_for("the cursor five cells right, two down", |s| {
        s.contains("(405, 274)")
    });
    tmux.keys(&["H", "H", "H", "H", "H", "K", "K", "K", "K"]);
    tmux.wait_for("the cursor on the glass sphere", |s| {
        s.contains("(400, 270)")
    });
    tmux.keys(&["Enter"]);
    // At 80 columns the tree's title drops the pixel; the status line names it.
    let screen = tmux.wait_for("the ray tree", |s| {
        s.contains("9 of 13 rays") && line_with(s, "rendered in").contains("(400, 270)")
    });
    assert!(
        line_with(&screen, "▼ camera").contains("glass s"),
        "the camera ray hits the glass sphere:\n{screen}"
    );
    assert!(
        line_with(&screen, "  ray  ").contains("share"),
        "the tree has a header:\n{screen}"
    );

    // Search the tree: the prompt is on the status line, Enter selects the first match.
    tmux.keys(&["/"]);
    tmux.wait_for("the search prompt", |s| s.contains("search rays /"));
    tmux.keys(&["t", "r", "a", "n", "s", "m", "i", "t", "t", "e", "d"]);
    tmux.wait_for("the typed query", |s| {
        s.contains("search rays /transmitted")
    });
    tmux.keys(&["Enter"]);
    let screen = tmux.wait_for("the first match", |s| {
        s.contains("match 1 of 4 for `transmitted`")
    });
    assert!(screen.contains("Inspector · transmitted ray"), "{screen}");

    // The inspector, focused, gets the wider column: its numbers and the source line show.
    tmux.keys(&["Tab"]);
    let screen = tmux.wait_for("the focused inspector", |s| {
        s.contains("┏ Inspector · transmitted ray, depth 1")
    });
    for wanted in [
        "ior           1.000 → 1.500",
        "object        glass sphere (sphere)",
        "coefficient   ██ 0.900 0.900 0.900  kt",
        "field         value  r     g     b",
    ] {
        assert!(screen.contains(wanted), "`{wanted}` on screen:\n{screen}");
    }
    assert!(
        line_with(&screen, "Source · ").contains("scenes/whitted.scene:20:1"),
        "{screen}"
    );
    assert!(
        line_with(&screen, "20 │").contains("sphere \"glass sphere\""),
        "the sphere's line shows:\n{screen}"
    );

    // Zoomed, the inspector has the whole screen: the colour sums can be read in full.
    tmux.keys(&["z"]);
    tmux.wait_for("the zoomed inspector", |s| {
        s.contains("zoomed: z back, Tab next")
    });
    tmux.keys(&["PageDown"]);
    let screen = tmux.wait_for("the returned colour", |s| s.contains("= returned"));
    assert!(
        line_with(&screen, "+ reflected").contains("kr × its colour"),
        "{screen}"
    );
    // Esc leaves the zoom, and does not quit.
    tmux.keys(&["Escape"]);
    tmux.wait_for("the layout again", |s| {
        s.contains("Ray tree") && !s.contains("zoomed: z back")
    });
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after q", |s| {
        s.contains("debugger exited with 0")
    });
}

/// The colour `whitted trace` gives a pixel of a scene file, as the debugger writes colours
/// (three decimals): the oracle for what the what-if popup shows.
fn traced_color(dir: &Path, scene: &str, pixel: &str) -> String {
    let output = Command::new(whitted())
        .current_dir(dir)
        .args(["trace", scene, "--pixel", pixel, "--json"])
        .output()
        .expect("whitted trace runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let tree: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    let color: Vec<String> = (0..3)
        .map(|i| format!("{:.3}", tree["color"][i].as_f64().expect("a colour")))
        .collect();
    color.join(" ")
}

/// What-if (issue 13, item 5): pick the glass sphere, open what-if, change the glass's ior
/// from 1.5 to 1; the popup shows the old and new colours (the new one as `whitted trace`
/// gives it for a copy of the scene edited by hand) and the tree diff; W writes the change
/// to the scene file on its line, and the debugger reloads it.
#[test]
fn what_if_changes_the_glass_ior_shows_the_diff_and_writes_it_back() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let original = std::fs::read_to_string(repository().join("scenes/whitted.scene"))
        .expect("the scene is readable");
    std::fs::write(dir.path().join("scene.scene"), &original).expect("writable");
    let edited = original.replace("ior 1.5", "ior 1.0");
    assert_ne!(edited, original);
    std::fs::write(dir.path().join("by-hand.scene"), &edited).expect("writable");
    let old_color = traced_color(dir.path(), "scene.scene", "400,270");
    let new_color = traced_color(dir.path(), "by-hand.scene", "400,270");
    assert_ne!(old_color, new_color, "the ior changes the pixel");

    let command = format!("'{}' debug scene.scene --pixel 400,270", whitted());
    let tmux = Tmux::start("whatif", dir.path(), &command, 120, 40);
    tmux.wait_for("the picked pixel", |s| {
        s.contains("Ray tree of (400, 270)") && s.contains("rendered in")
    });
    tmux.keys(&["w"]);
    let screen = tmux.wait_for("the what-if popup", |s| {
        s.contains("What if · pixel (400, 270)")
    });
    assert!(
        line_with(&screen, "▶").contains("material glass  ior          1.5"),
        "the glass's ior is listed and selected:\n{screen}"
    );
    tmux.keys(&["Enter", "BSpace", "BSpace", "BSpace"]);
    tmux.type_text("1.0");
    tmux.keys(&["Enter"]);
    let screen = tmux.wait_for("the re-traced colour", |s| s.contains("   new ██"));
    let colours = line_with(&screen, "   new ██");
    assert!(
        colours.contains(&format!("old ██ {old_color}")),
        "old colour {old_color}:\n{screen}"
    );
    assert!(
        colours.contains(&format!("new ██ {new_color}")),
        "new colour {new_color} (whitted trace of the scene edited by hand):\n{screen}"
    );
    assert!(
        screen.contains("first difference: ior of material glass (at glass sphere): 1.5 → 1"),
        "{screen}"
    );
    assert!(
        line_with(&screen, "~   transmitted").contains("glass sphere"),
        "the changed transmitted ray is listed:\n{screen}"
    );

    tmux.keys(&["W"]);
    // The write reloads the scene, which closes the popup: its values were of the old one.
    tmux.wait_for("the write and the reload", |s| {
        s.contains("reloaded scene.scene; what-if closed")
    });
    let written = std::fs::read_to_string(dir.path().join("scene.scene")).expect("readable");
    assert_eq!(written, original.replace("ior 1.5", "ior 1"));
    // The reloaded scene renders the new colour (once its render reaches the pixel).
    tmux.wait_for("the popup closed and the new colour rendered", |s| {
        !s.contains("What if") && line_with(s, "(400, 270) ██").contains(&new_color)
    });
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
}

/// Queries in the debugger (issue 13, item 6): `:` runs a predicate over the image, the
/// status line counts the matches as `whitted query` does, and `n` goes from the cursor to the
/// next match in row order and traces it.
#[test]
fn a_query_marks_its_pixels_and_n_goes_to_the_first() {
    let expr = "hit(\"mirror sphere\") and depth >= 3";
    let output = Command::new(whitted())
        .current_dir(repository())
        .args([
            "query",
            "scenes/whitted.scene",
            expr,
            "--json",
            "--limit",
            "1000000",
        ])
        .output()
        .expect("whitted query runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let answer: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    let count = answer["count"].as_u64().expect("a count");
    // The cursor starts at (320, 240): the next match in row order is the oracle.
    let pixels: Vec<(u64, u64)> = answer["pixels"]
        .as_array()
        .expect("the matches")
        .iter()
        .map(|p| {
            (
                p["pixel"][0].as_u64().unwrap(),
                p["pixel"][1].as_u64().unwrap(),
            )
        })
        .collect();
    assert_eq!(pixels.len() as u64, count);
    let index = pixels
        .iter()
        .position(|&(x, y)| (y, x) > (240, 320))
        .expect("a match below the middle");
    let (x, y) = pixels[index];
    let first = format!("({x}, {y})");

    let command = format!("'{}' debug scenes/whitted.scene", whitted());
    let tmux = Tmux::start("query", &repository(), &command, 120, 40);
    tmux.wait_for("the finished image", |s| s.contains("rendered in"));
    tmux.keys(&[":"]);
    tmux.wait_for("the prompt", |s| s.contains(" query: "));
    tmux.type_text(expr);
    tmux.keys(&["Enter"]);
    let screen = tmux.wait_for("the query's answer", |s| s.contains("pixels match"));
    assert!(
        screen.contains(&format!("{count} pixels match {expr}")),
        "{count} pixels, as whitted query says:\n{screen}"
    );
    assert!(
        screen.contains(&format!("· query: {count} px")),
        "the overlay is named in the image's title:\n{screen}"
    );
    tmux.keys(&["n"]);
    let screen = tmux.wait_for("the first match traced", |s| {
        s.contains(&format!("Ray tree of {first}"))
    });
    assert!(
        screen.contains(&format!("match {} of {count}", index + 1)),
        "{screen}"
    );
    assert!(
        screen.contains(&format!("{first} ██")),
        "the status line shows the cursor on {first}:\n{screen}"
    );
    tmux.keys(&["Escape"]);
    tmux.wait_for("the overlay cleared", |s| {
        s.contains("cleared the query's matches")
    });
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after quitting", |s| {
        s.contains("debugger exited with 0")
    });
}

// Issue 27, "the debugger at 80x24": what a newcomer's trial at the common terminal size found.

/// The `--pixel 400,270` glass-sphere pixel of scenes/whitted.scene in a `width × height`
/// terminal, its tree shown.
fn glass_pixel_at(name: &str, width: u16, height: u16) -> Tmux {
    let command = format!("'{}' debug scenes/whitted.scene --pixel 400,270", whitted());
    let tmux = Tmux::start(name, &repository(), &command, width, height);
    tmux.wait_for("the tree of --pixel", |s| {
        s.contains("9 of 13 rays") && s.contains("rendered in")
    });
    tmux
}

/// The right column of an 80x24 screen when the left one has the focus (the inspector's
/// and the source pane's text), one string per line, without the borders.
fn right_column(screen: &str, from: usize) -> Vec<String> {
    screen
        .lines()
        .map(|line| {
            line.chars()
                .skip(from)
                .collect::<String>()
                .trim_matches(|c: char| "│┃ ".contains(c))
                .to_string()
        })
        .collect()
}

#[test]
fn at_80x24_the_unfocused_inspector_shows_values_first_and_whole_source_locations() {
    let tmux = glass_pixel_at("inspector80", 80, 24);
    let screen = tmux.wait_for("the inspector", |s| s.contains("Inspector · camera"));
    // The image has the keyboard: the inspector is the narrow right column (from column 48).
    let inspector = right_column(&screen, 48);
    assert!(
        inspector.iter().any(|l| l == "scenes/whitted.scene:20:1"),
        "the glass sphere's definition on a line by itself:\n{screen}"
    );
    // The value first, whole; its field name after it, on the next line if need be.
    let pixel = inspector
        .iter()
        .position(|l| l.contains("pixel 400,270"))
        .unwrap_or_else(|| panic!("the pixel's line:\n{screen}"));
    assert!(
        inspector[pixel.saturating_sub(1)..=pixel]
            .iter()
            .any(|l| l.starts_with("██ 0.189 0.292 0.693")),
        "the value first, whole:\n{screen}"
    );
}

/// The ray tree pane's header and rows as character vectors, cut at the pane's right border.
fn tree_rows(screen: &str) -> (Vec<char>, Vec<Vec<char>>) {
    let lines: Vec<&str> = screen.lines().collect();
    let at = lines
        .iter()
        .position(|l| l.contains("  ray  ") && l.contains("share"))
        .unwrap_or_else(|| panic!("the tree's header:\n{screen}"));
    let header: Vec<char> = lines[at].chars().collect();
    let border = header
        .iter()
        .skip(1)
        .position(|c| "│┃".contains(*c))
        .map_or(header.len(), |p| p + 1);
    let cut = |line: &str| -> Vec<char> { line.chars().take(border).collect() };
    let rows = lines[at + 1..]
        .iter()
        .take_while(|l| !l.starts_with('└') && !l.starts_with('┗'))
        .map(|l| cut(l))
        .filter(|l| l.contains(&'█'))
        .collect();
    (cut(lines[at]), rows)
}

/// The words of `line` from `from` on, with the column each starts at.
fn words_from(line: &[char], from: usize) -> Vec<(usize, String)> {
    let mut words = Vec::new();
    let mut current: Option<(usize, String)> = None;
    for (i, &c) in line.iter().enumerate().skip(from) {
        if c == ' ' || "│┃".contains(c) {
            words.extend(current.take());
        } else if let Some((_, word)) = &mut current {
            word.push(c);
        } else {
            current = Some((i, c.to_string()));
        }
    }
    words.extend(current);
    words
}

/// In every row, the swatch stands under `share` and each number under its `r`, `g` or `b`,
/// whole (two decimals, not cut), and the depth after the kind is whole too.
fn assert_tree_columns(screen: &str) {
    let (header, rows) = tree_rows(screen);
    let header_text: String = header.iter().collect();
    let share = header_text
        .find("share")
        .map(|byte| header_text[..byte].chars().count())
        .unwrap_or_else(|| panic!("a share header:\n{screen}"));
    let channels = words_from(&header, share + 5);
    assert!(!rows.is_empty(), "{screen}");
    for row in rows {
        let text: String = row.iter().collect();
        let swatch = row.iter().position(|&c| c == '█').unwrap();
        assert!(
            (share..share + 5).contains(&swatch) && (share..share + 5).contains(&(swatch + 1)),
            "the swatch under `share`:\n{header_text}\n{text}\n{screen}"
        );
        let under_share: String = row.iter().skip(share).take(5).collect();
        assert!(
            under_share.chars().all(|c| c == ' ' || c == '█'),
            "only the swatch under `share`:\n{header_text}\n{text}\n{screen}"
        );
        let numbers = words_from(&row, share + 5);
        assert_eq!(
            numbers.len(),
            channels.len(),
            "as many numbers as headers:\n{header_text}\n{text}\n{screen}"
        );
        for ((at, number), (channel_at, channel)) in numbers.iter().zip(&channels) {
            let whole = number.split_once('.').is_some_and(|(units, decimals)| {
                !units.is_empty()
                    && units.chars().all(|c| c.is_ascii_digit())
                    && decimals.len() == 2
                    && decimals.chars().all(|c| c.is_ascii_digit())
            });
            assert!(whole, "`{number}` is whole:\n{text}\n{screen}");
            assert!(
                (*at..at + number.chars().count()).contains(channel_at),
                "`{channel}` over `{number}`:\n{header_text}\n{text}\n{screen}"
            );
        }
        let depth_whole = words_from(&row, 0).iter().any(|(_, word)| {
            word.len() > 1 && word.starts_with('d') && word[1..].chars().all(|c| c.is_ascii_digit())
        });
        assert!(depth_whole, "the depth is whole:\n{text}\n{screen}");
    }
}

#[test]
fn the_tree_s_headers_stand_over_their_columns_at_80x24_and_wide() {
    let tmux = glass_pixel_at("headers80", 80, 24);
    // Unfocused (swatches only), then focused (with the numbers).
    assert_tree_columns(&tmux.screen());
    tmux.keys(&["Tab"]);
    let screen = tmux.wait_for("the focused tree", |s| s.contains("┏ Ray tree"));
    assert_tree_columns(&screen);
    assert!(
        line_with(&screen, "  ray  ").contains("share    r    g    b"),
        "the focused tree has room for the numbers:\n{screen}"
    );
    drop(tmux);
    let tmux = glass_pixel_at("headers160", 160, 48);
    assert_tree_columns(&tmux.screen());
}

#[test]
fn deep_rows_keep_their_digits_and_show_fewer_columns() {
    // A room of mirrors: rays 64 deep.
    let command = format!(
        "'{}' debug scenes/ray-explosion.scene --pixel 32,24",
        whitted()
    );
    let tmux = Tmux::start("deep", &repository(), &command, 80, 24);
    tmux.wait_for("the tree of --pixel", |s| {
        s.contains("Ray tree") && s.contains("rendered in")
    });
    tmux.keys(&["Tab", "End"]);
    let screen = tmux.wait_for("the deepest rows", |s| {
        s.contains("┏ Ray tree") && s.contains("Inspector · shadow")
    });
    assert_tree_columns(&screen);
    // Unfocused, the narrow tree keeps its swatches and depths whole too.
    tmux.keys(&["Tab"]);
    let screen = tmux.wait_for("the inspector focused", |s| s.contains("┏ Inspector"));
    assert_tree_columns(&screen);
}

#[test]
fn the_query_prompt_opens_empty_recalls_history_and_edits_like_a_shell() {
    let tmux = glass_pixel_at("prompt80", 80, 24);
    tmux.keys(&[":"]);
    tmux.wait_for("the prompt", |s| s.contains(" query: "));
    tmux.type_text("tir and hit(\"nope\")");
    tmux.keys(&["Enter"]);
    tmux.wait_for("the query's error", |s| s.contains("query error at column"));
    tmux.keys(&[":"]);
    let screen = tmux.wait_for("the prompt again", |s| s.contains(" query: "));
    assert!(
        line_with(&screen, " query: ").starts_with(" query:     Enter runs it"),
        "the prompt opens empty:\n{screen}"
    );
    tmux.keys(&["Up"]);
    tmux.wait_for("the failed query recalled", |s| {
        line_with(s, " query: ").contains("query: tir and hit(\"nope\")")
    });
    tmux.keys(&["C-w"]);
    tmux.wait_for("the word before the cursor deleted", |s| {
        line_with(s, " query: ").starts_with(" query: tir and     Enter")
    });
    tmux.keys(&["C-u"]);
    tmux.wait_for("the line cleared", |s| {
        line_with(s, " query: ").starts_with(" query:     Enter")
    });
    tmux.keys(&["Escape"]);
    tmux.wait_for("the prompt closed", |s| !s.contains(" query: "));
}

#[test]
fn keys_act_on_the_focused_explanation() {
    let tmux = glass_pixel_at("explainkeys", 80, 24);
    // From the tree, x opens the explanation: it takes the keyboard, so z zooms it.
    tmux.keys(&["Tab"]);
    tmux.wait_for("the focused tree", |s| s.contains("┏ Ray tree"));
    tmux.keys(&["x"]);
    let screen = tmux.wait_for("the explanation", |s| s.contains("Findings"));
    assert!(
        screen.contains("┏ Explanation"),
        "the explanation has the keyboard:\n{screen}"
    );
    tmux.keys(&["z"]);
    let screen = tmux.wait_for("the zoomed pane", |s| s.contains("zoomed: z back"));
    assert!(
        screen.contains("Explanation of (400, 270)") && !screen.contains("Ray tree"),
        "the explanation is zoomed, not the tree:\n{screen}"
    );
}

/// `whitted mit6837 ... -gui` opens the debugger on the course scene with the command
/// line's settings (its `-size`, and its samples and filter in the render), after writing
/// the image it was asked for; `q` ends it with exit code 0.
#[test]
fn the_course_s_gui_flag_opens_the_debugger_with_its_settings() {
    let out = tempfile::tempdir().expect("a temporary directory");
    let scene = repository().join("scenes/mit6837/spheres-orthographic.txt");
    let command = format!(
        "'{}' mit6837 -input '{}' -size 60 40 -jittered_samples 4 -gaussian_filter 0.6 \
         -output out.png -gui",
        whitted(),
        scene.display()
    );
    let tmux = Tmux::start("gui", out.path(), &command, 120, 40);
    let screen = tmux.wait_for("the finished image", |s| s.contains("rendered in"));
    assert!(screen.contains("Image 60×40"), "{screen}");
    assert!(
        out.path().join("out.png").is_file(),
        "the image is written first"
    );
    tmux.keys(&["q"]);
    tmux.wait_for("the debugger's end", |s| {
        s.contains("debugger exited with 0")
    });
}
