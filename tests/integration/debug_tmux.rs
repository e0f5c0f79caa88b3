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

    /// Polls the screen until `ready` holds; fails with the last screen after [`PATIENCE`].
    fn wait_for(&self, what: &str, ready: impl Fn(&str) -> bool) -> String {
        let started = Instant::now();
        loop {
            let screen = self.screen();
            if ready(&screen) {
                return screen;
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
        line_with(&screen, "transmitted d1").contains("glass sphere (inside)"),
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
    let screen = tmux.wait_for("the tree of --pixel", |s| {
        s.contains("Ray tree of (400, 270)") && s.contains("rendered in")
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
    let screen = tmux.wait_for("the ray tree of the pixel", |s| {
        s.contains("Ray tree of (133, 317)") && s.contains("Source · ")
    });
    assert!(
        line_with(&screen, "camera      d0").contains("sphere #0"),
        "{screen}"
    );
    assert!(
        line_with(&screen, "Source · ").contains("spheres-orthographic.txt:31:5"),
        "{screen}"
    );
    assert!(
        line_with(&screen, "31 │").contains("Sphere {"),
        "the definition's line is shown:\n{screen}"
    );
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
    let screen = tmux.wait_for("the ray tree", |s| s.contains("Ray tree of (400, 270)"));
    assert!(
        line_with(&screen, "▼ camera").contains("glass sph"),
        "the camera ray hits the glass sphere:\n{screen}"
    );
    assert!(
        screen.contains("what it met"),
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
        s.contains("Ray tree of (400, 270)") && !s.contains("zoomed: z back")
    });
    tmux.keys(&["q"]);
    tmux.wait_for("the shell after q", |s| {
        s.contains("debugger exited with 0")
    });
}
