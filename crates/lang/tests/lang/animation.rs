//! The animation clock (`frame`, `clock`, `fps` from `CompileOptions::frame` and the scene's
//! `frames`, `first_frame` and `fps` settings) and its helpers (`lerp`, `smoothstep`,
//! `keyframes`), with values worked out by hand.

use whitted_ir::DVec3;
use whitted_lang::{Compilation, CompileOptions};

use crate::support::*;

fn at_frame(input: &str, frame: Option<u32>) -> Compilation {
    let options = CompileOptions {
        frame,
        ..CompileOptions::default()
    };
    compile_with(input, &mut MapLoader::default(), &options)
}

/// `<frame, clock, fps>` of `settings` at `frame`.
fn clock_at(settings: &str, frame: Option<u32>) -> DVec3 {
    let text = format!("settings {{ {settings} }}\nsphere {{ center <frame, clock, fps> }}\n");
    let compilation = at_frame(&text, frame);
    match &compilation.scene {
        Some(scene) => first_center(scene),
        None => panic!("did not compile:\n{}", output(&compilation)),
    }
}

#[test]
fn the_clock_runs_from_0_at_the_first_frame_to_1_at_the_last() {
    // Frames 10 to 30: the middle frame 20 is half-way, 15 a quarter.
    let settings = "first_frame 10 frames 21 fps 30";
    assert_eq!(clock_at(settings, Some(10)), DVec3::new(10.0, 0.0, 30.0));
    assert_eq!(clock_at(settings, Some(15)), DVec3::new(15.0, 0.25, 30.0));
    assert_eq!(clock_at(settings, Some(20)), DVec3::new(20.0, 0.5, 30.0));
    assert_eq!(clock_at(settings, Some(30)), DVec3::new(30.0, 1.0, 30.0));
    // No frame asked for: the first frame.
    assert_eq!(clock_at(settings, None), DVec3::new(10.0, 0.0, 30.0));
    // The settings block may come after the clock is read.
    let late = "sphere { center <frame, clock, fps> }\nsettings { frames 5 }\n";
    let compilation = at_frame(late, Some(2));
    let Some(scene) = &compilation.scene else {
        panic!("{}", output(&compilation));
    };
    assert_eq!(first_center(scene), DVec3::new(2.0, 0.5, 24.0));
}

#[test]
fn a_still_has_clock_0_and_the_default_rate() {
    assert_eq!(clock_at("", None), DVec3::new(0.0, 0.0, 24.0));
    assert_eq!(clock_at("", Some(7)), DVec3::new(7.0, 0.0, 24.0));
    // A frame outside the range gives a clock outside [0, 1].
    assert_eq!(clock_at("frames 3", Some(4)), DVec3::new(4.0, 2.0, 24.0));
}

#[test]
fn a_frame_range_that_depends_on_the_clock_is_an_error() {
    // Compiled at clock 0 the range is frames 0 to 1, where frame 1 has clock 1 and 6 frames.
    let compilation = at_frame("settings { frames 2 + clock * 4 }\nsphere { }\n", Some(1));
    assert!(compilation.scene.is_none());
    let text = output(&compilation);
    assert!(text.contains("must not depend on `frame`"), "{text}");
}

#[test]
fn a_name_the_scene_defines_hides_the_clock() {
    let compilation = at_frame(
        "let frame = 42;\nsphere { center <frame, 0, 0> }\n",
        Some(3),
    );
    let Some(scene) = &compilation.scene else {
        panic!("{}", output(&compilation));
    };
    assert_eq!(first_center(scene).x, 42.0);
}

#[test]
fn lerp_and_smoothstep_by_hand() {
    assert_eq!(number("lerp(2, 6, 0.25)"), 3.0);
    assert_eq!(
        vector("lerp(<0, 0, 0>, <4, 8, -4>, 0.5)"),
        DVec3::new(2.0, 4.0, -2.0)
    );
    // u = 0.5: 3/4 - 2/8 = 0.5; u = 0.25: 3/16 - 2/64 = 0.15625.
    assert_eq!(number("smoothstep(0, 2, 1)"), 0.5);
    assert_eq!(number("smoothstep(0, 4, 1)"), 0.15625);
    assert_eq!(number("smoothstep(1, 2, 0)"), 0.0);
    assert_eq!(number("smoothstep(1, 2, 5)"), 1.0);
}

#[test]
fn keyframes_go_in_straight_lines_and_hold_at_the_ends() {
    let keys = "[[0, 0], [1, 10], [3, 20]]";
    assert_eq!(number(&format!("keyframes({keys}, -1)")), 0.0);
    assert_eq!(number(&format!("keyframes({keys}, 0)")), 0.0);
    assert_eq!(number(&format!("keyframes({keys}, 0.5)")), 5.0);
    assert_eq!(number(&format!("keyframes({keys}, 1)")), 10.0);
    assert_eq!(number(&format!("keyframes({keys}, 2)")), 15.0);
    assert_eq!(number(&format!("keyframes({keys}, 9)")), 20.0);
    assert_eq!(
        vector("keyframes([[0, <0, 0, 0>], [2, <2, 4, 6>]], 0.5)"),
        DVec3::new(0.5, 1.0, 1.5)
    );
    // One key: its value everywhere. Two keys at one time: a jump.
    assert_eq!(number("keyframes([[5, 7]], 0)"), 7.0);
    let jump = "[[0, 0], [1, 1], [1, 5], [2, 6]]";
    assert_eq!(number(&format!("keyframes({jump}, 0.5)")), 0.5);
    assert_eq!(number(&format!("keyframes({jump}, 1)")), 5.0);
    assert_eq!(number(&format!("keyframes({jump}, 1.5)")), 5.5);
}

#[test]
fn bad_keys_are_located_errors_that_name_the_key() {
    let cases = [
        ("keyframes([], 0)", "needs at least one key"),
        (
            "keyframes([[0, 1], [2, 3], [1, 4]], 0)",
            "key 2 is at 1 after key 1 at 2",
        ),
        (
            "keyframes([[0, 1], [1, <1, 1, 1>]], 0)",
            "key 0 is a number, key 1 is a vector",
        ),
        (
            "keyframes([[0, 1], [1]], 0)",
            "key 1 of `keyframes` must be `[time, value]`",
        ),
        (
            "keyframes([[0, 1], 3], 0)",
            "key 1 of `keyframes` must be `[time, value]`",
        ),
        ("keyframes(3, 0)", "needs an array of keys"),
        (
            "keyframes([[0, 1]], <0, 0, 0>)",
            "needs a number for the time",
        ),
        ("smoothstep(1, 1, 0)", "two different edges"),
    ];
    for (expr, expected) in cases {
        let text = format!("sphere {{ center <{expr}, 0, 0> }}\n");
        let compilation = at_frame(&text, None);
        assert!(compilation.scene.is_none(), "{expr} compiled");
        let shown = output(&compilation);
        assert!(shown.contains(expected), "{expr}:\n{shown}");
        // Located: the message points into the scene's line.
        assert!(
            shown.contains("test.scene:1:"),
            "{expr} is not located:\n{shown}"
        );
    }
}
