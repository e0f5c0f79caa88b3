//! Animation through the real binary (issue 30, part 1): `--frame` gives the scene its
//! `frame` and `clock`, a frame renders as the same scene with those written as constants,
//! `render` writes frames through a pattern, into an animated PNG or GIF, and refuses what
//! would go wrong (frames overwriting each other, a broken pattern, a video without ffmpeg).

use std::path::{Path, PathBuf};

use crate::support::{ok, run};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn stderr(output: &std::process::Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// The RGB bytes of the first image of a PNG (the still, or an APNG's first frame).
fn png_pixels(path: &Path) -> Vec<u8> {
    let file = std::fs::File::open(path).expect("the PNG exists");
    let decoder = png::Decoder::new(std::io::BufReader::new(file));
    let mut reader = decoder.read_info().expect("a PNG");
    let mut buffer = vec![0; reader.output_buffer_size().expect("a size")];
    let info = reader.next_frame(&mut buffer).expect("a frame");
    buffer.truncate(info.buffer_size());
    buffer
}

#[test]
fn the_clock_is_0_at_the_first_frame_a_half_in_the_middle_and_1_at_the_last() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("clock.scene");
    std::fs::write(
        &scene,
        "settings { first_frame 10 frames 21 fps 30 }\n\
         sphere { center <frame, clock, fps> material { diffuse 0.5 } }\n",
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let center = |frame: Option<&str>| {
        let mut args = vec!["ir", scene];
        if let Some(frame) = frame {
            args.extend(["--frame", frame]);
        }
        let text = ok(&args);
        let line = text.lines().find(|l| l.contains("sphere")).unwrap_or("");
        line.split_once("center ")
            .and_then(|(_, rest)| rest.split_once('>'))
            .map(|(center, _)| center.trim_start_matches('<').to_string())
            .unwrap_or_default()
    };
    // (frame - 10) / (30 - 10).
    assert_eq!(center(Some("10")), "10, 0, 30");
    assert_eq!(center(Some("20")), "20, 0.5, 30");
    assert_eq!(center(Some("25")), "25, 0.75, 30");
    assert_eq!(center(Some("30")), "30, 1, 30");
    assert_eq!(center(None), "10, 0, 30");
}

/// Frame `frame` of `scene` against a copy of it with `clock` and `frame` written as the
/// constants they are at that frame (and the animation's settings left out): the same bytes.
fn frame_matches_constant_copy(scene: &str, settings: &str, frame: u32, last: u32) {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join(scene)).unwrap();
    assert!(text.contains(settings), "{scene} has no `{settings}`");
    // Without the comments, which talk about the clock.
    let code: String = text
        .lines()
        .filter(|line| !line.trim_start().starts_with("//"))
        .map(|line| format!("{line}\n"))
        .collect();
    let constant = code
        .replace(settings, "")
        .replace("clock", &format!("({frame} / {last})"));
    assert!(!constant.contains("clock") && !constant.contains(settings));
    let copy = dir.path().join("constant.scene");
    std::fs::write(&copy, constant).unwrap();
    let animated = dir.path().join("animated.png");
    let still = dir.path().join("still.png");
    let frame_text = frame.to_string();
    ok(&[
        "render",
        scene,
        "--frame",
        &frame_text,
        "-o",
        animated.to_str().unwrap(),
        "--quiet",
    ]);
    ok(&[
        "render",
        copy.to_str().unwrap(),
        "-o",
        still.to_str().unwrap(),
        "--quiet",
    ]);
    assert_eq!(
        png_pixels(&animated),
        png_pixels(&still),
        "{scene} frame {frame}"
    );
    // And the frame is not the first one: the scene moved.
    let first = dir.path().join("first.png");
    ok(&[
        "render",
        scene,
        "--frame",
        "0",
        "-o",
        first.to_str().unwrap(),
        "--quiet",
    ]);
    assert_ne!(
        png_pixels(&animated),
        png_pixels(&first),
        "{scene} does not move"
    );
}

#[test]
fn a_frame_renders_as_the_scene_with_its_clock_written_as_a_constant() {
    frame_matches_constant_copy("scenes/turntable.scene", "frames 24 fps 12", 6, 23);
    frame_matches_constant_copy("scenes/flythrough.scene", "frames 16 fps 8", 11, 15);
}

#[test]
fn frames_2_to_4_write_exactly_three_files_named_by_the_pattern() {
    let dir = tempfile::tempdir().unwrap();
    let pattern = dir.path().join("f-{frame:03}.png");
    ok(&[
        "render",
        "scenes/turntable.scene",
        "--frames",
        "2..=4",
        "--width",
        "32",
        "--height",
        "24",
        "-o",
        pattern.to_str().unwrap(),
    ]);
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["f-002.png", "f-003.png", "f-004.png"]);
    // Each is that frame, as `--frame` renders it.
    let single = dir.path().join("single.png");
    ok(&[
        "render",
        "scenes/turntable.scene",
        "--frame",
        "3",
        "--width",
        "32",
        "--height",
        "24",
        "-o",
        single.to_str().unwrap(),
    ]);
    assert_eq!(
        png_pixels(&dir.path().join("f-003.png")),
        png_pixels(&single)
    );
    assert_ne!(
        png_pixels(&dir.path().join("f-002.png")),
        png_pixels(&single)
    );
}

#[test]
fn a_folder_gets_the_scenes_name_and_four_digits() {
    let dir = tempfile::tempdir().unwrap();
    ok(&[
        "render",
        "scenes/turntable.scene",
        "--frames",
        "0..2",
        "--width",
        "16",
        "--height",
        "12",
        "-o",
        dir.path().to_str().unwrap(),
    ]);
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["turntable-0000.png", "turntable-0001.png"]);
}

#[test]
fn an_apng_holds_every_frame_and_its_first_is_the_still_of_frame_0() {
    let dir = tempfile::tempdir().unwrap();
    let apng = dir.path().join("turn.apng");
    let still = dir.path().join("still.png");
    let size = ["--width", "40", "--height", "30"];
    let mut args = vec!["render", "scenes/turntable.scene", "--frames", "0..=3"];
    args.extend(size);
    args.extend(["-o", apng.to_str().unwrap()]);
    ok(&args);
    let mut args = vec!["render", "scenes/turntable.scene", "--frame", "0"];
    args.extend(size);
    args.extend(["-o", still.to_str().unwrap()]);
    ok(&args);

    let file = std::fs::File::open(&apng).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let control = reader.info().animation_control().expect("an animated PNG");
    assert_eq!(control.num_frames, 4);
    // The turntable's 12 frames per second.
    let mut frames = Vec::new();
    for _ in 0..4 {
        let mut buffer = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buffer).expect("every frame decodes");
        buffer.truncate(info.buffer_size());
        let control = reader.info().frame_control().expect("a frame control");
        assert_eq!((control.delay_num, control.delay_den), (1, 12));
        frames.push(buffer);
    }
    assert_eq!(frames[0], png_pixels(&still), "frame 0 is not the still");
    assert_ne!(frames[0], frames[1], "the frames do not move");
}

#[test]
fn a_gif_has_a_frame_per_frame_rendered() {
    use image::AnimationDecoder;
    let dir = tempfile::tempdir().unwrap();
    let gif = dir.path().join("turn.gif");
    ok(&[
        "render",
        "scenes/turntable.scene",
        "--frames",
        "5..=9",
        "--width",
        "24",
        "--height",
        "18",
        "-o",
        gif.to_str().unwrap(),
    ]);
    let file = std::io::BufReader::new(std::fs::File::open(&gif).unwrap());
    let decoder = image::codecs::gif::GifDecoder::new(file).expect("a GIF");
    let frames = decoder
        .into_frames()
        .collect_frames()
        .expect("frames decode");
    assert_eq!(frames.len(), 5);
    // 12 frames per second: 1000/12 ms, which GIF keeps in hundredths (8).
    let (numer, denom) = frames[0].delay().numer_denom_ms();
    assert_eq!(numer / denom, 80);
}

#[test]
fn frame_selects_what_trace_and_explain_see() {
    let pixel = ["--pixel", "40,70"];
    let trace = |frame: &str| {
        let mut args = vec!["trace", "scenes/turntable.scene", "--frame", frame];
        args.extend(pixel);
        ok(&args)
    };
    // The crate stands at this pixel at frame 0 and has turned away by frame 6.
    assert!(trace("0").contains("crate"), "{}", trace("0"));
    assert!(!trace("6").contains("crate"), "{}", trace("6"));
    let explain = ok(&[
        "explain",
        "scenes/turntable.scene",
        "--frame",
        "6",
        "--pixel",
        "40,70",
    ]);
    assert!(!explain.contains("crate"), "{explain}");
}

#[test]
fn bad_frame_flags_and_outputs_are_refused_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let at = |name: &str| dir.path().join(name).to_string_lossy().into_owned();
    let cases: Vec<(Vec<String>, i32, &str)> = vec![
        (
            vec!["--frame".into(), "4294967296".into()],
            2,
            "4294967296 is not in 0..=4294967295",
        ),
        (
            vec!["--frame".into(), "-1".into()],
            2,
            "unexpected argument '-1'",
        ),
        (
            vec!["--frames".into(), "5..=2".into()],
            2,
            "runs backwards: the first frame (5) must not be after the last (2)",
        ),
        (
            vec!["-o".into(), at("out-{frame.png")],
            2,
            "has `{frame` without its closing `}`",
        ),
        (
            vec!["-o".into(), at("out.png")],
            2,
            "24 frames are to be rendered and would overwrite each other",
        ),
        (
            vec![
                "--frames".into(),
                "0..=99999".into(),
                "--width".into(),
                "4000".into(),
                "--height".into(),
                "3000".into(),
                "-o".into(),
                at("huge.apng"),
            ],
            2,
            "the animation pixels limit",
        ),
    ];
    for (flags, code, expected) in cases {
        let mut args = vec!["render", "scenes/turntable.scene"];
        args.extend(flags.iter().map(String::as_str));
        let output = run(&args);
        let message = stderr(&output);
        assert_eq!(output.status.code(), Some(code), "{flags:?}: {message}");
        assert!(message.contains(expected), "{flags:?}: {message}");
        assert!(!message.contains("panicked"), "{flags:?}: {message}");
    }
    // Nothing was written by any of them.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn a_video_without_ffmpeg_says_that_ffmpeg_is_needed() {
    let dir = tempfile::tempdir().unwrap();
    let video = dir.path().join("turn.mp4");
    // A PATH with no ffmpeg on it, whatever this machine has.
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_whitted"))
        .current_dir(root())
        .env("NO_COLOR", "1")
        .env("PATH", dir.path())
        .args(["render", "scenes/turntable.scene", "-o"])
        .arg(&video)
        .output()
        .unwrap();
    let message = stderr(&output);
    assert_eq!(output.status.code(), Some(1), "{message}");
    assert!(message.contains("needs ffmpeg"), "{message}");
    assert!(!video.exists());
}

#[test]
fn a_video_through_ffmpeg_holds_every_frame_and_is_not_private() {
    let has = |program: &str| {
        std::process::Command::new(program)
            .arg("-version")
            .output()
            .is_ok_and(|o| o.status.success())
    };
    if !has("ffmpeg") || !has("ffprobe") {
        eprintln!(
            "ffmpeg is not installed here: the video path is not run (apt-get install ffmpeg)"
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let video = dir.path().join("turn.mp4");
    let video_text = video.to_str().unwrap();
    let args = [
        "render",
        "scenes/turntable.scene",
        "--frames",
        "0..=5",
        "-o",
        video_text,
    ];
    crate::support::ok(&args);
    let probe = std::process::Command::new("ffprobe")
        .args(["-v", "error", "-count_frames", "-show_entries"])
        .args([
            "stream=nb_read_frames,width,height",
            "-of",
            "csv=p=0",
            video_text,
        ])
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&probe.stdout).trim(), "160,120,6");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(&video).unwrap().permissions().mode();
        assert_ne!(mode & 0o044, 0, "the video is private: {mode:o}");
    }
}
