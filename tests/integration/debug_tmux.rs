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
    let out = tempfile::tempdir().expect("a temporary directory");
    let scene = repository().join("scenes/whitted.scene");
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
    tmux.keys(&["L", "L", "L", "L", "L", "L", "L", "L", "J", "J", "J"]);
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

    // Export the tree as JSON into the working directory.
    tmux.keys(&["e"]);
    tmux.wait_for("the export message", |s| s.contains("wrote the ray tree"));
    let exported = out.path().join("whitted-400-270.ray-tree.json");
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
    tmux.keys(&["Escape"]);
    tmux.wait_for("the shell after Esc", |s| {
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
    tmux.wait_for("the write and the reload", |s| {
        s.contains("wrote scene.scene:15") && s.contains("reloaded scene.scene")
    });
    let written = std::fs::read_to_string(dir.path().join("scene.scene")).expect("readable");
    assert_eq!(written, original.replace("ior 1.5", "ior 1"));
    tmux.keys(&["Escape"]);
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
