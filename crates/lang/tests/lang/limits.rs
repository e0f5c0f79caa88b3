//! Bad input never crashes, hangs or eats the machine: deep nesting far past the limits is
//! refused with a located error (no stack overflow), and nesting just inside the limits works.

use whitted_lang::{CompileOptions, Limits};

use crate::support::*;

fn first_error_of(input: &str) -> String {
    let compilation = compile(input);
    let error = compilation.diagnostics.iter().find(|d| d.is_error());
    match error {
        Some(d) => {
            assert!(d.span.is_some(), "no span on: {}", d.message);
            d.message.clone()
        }
        None => panic!("expected an error"),
    }
}

#[test]
fn a_hundred_thousand_brackets_are_refused_not_overflowed() {
    let parens = format!("let x = {}1{};", "(".repeat(100_000), ")".repeat(100_000));
    assert!(first_error_of(&parens).contains("nesting limit is 256"));
    let braces = format!("{}{}", "union {".repeat(100_000), "}".repeat(100_000));
    assert!(first_error_of(&braces).contains("nesting limit is 256"));
    let unclosed = "group { ".repeat(100_000);
    assert!(first_error_of(&unclosed).contains("nesting limit is 256"));
    let vectors = format!(
        "let x = {}1{};",
        "<".repeat(100_000),
        ", 0, 0>".repeat(100_000)
    );
    assert!(first_error_of(&vectors).starts_with("vectors are nested too deeply"));
    let minus = format!("let x = {}1;", "-".repeat(100_000));
    assert!(first_error_of(&minus).starts_with("this expression is too long"));
    let not = format!("let x = {}true;", "!".repeat(100_000));
    assert!(first_error_of(&not).starts_with("this expression is too long"));
    let fields = format!("let x = <1, 2, 3>{};", ".x".repeat(100_000));
    assert!(first_error_of(&fields).starts_with("this is nested too deeply"));
}

#[test]
fn nesting_just_inside_the_limits_compiles() {
    let parens = format!(
        "sphere {{ radius {}1{} }}",
        "(".repeat(250),
        ")".repeat(250)
    );
    scene(&parens);
    let unions = format!("{}sphere {{ }}{}", "union { ".repeat(250), " }".repeat(250));
    assert_eq!(scene(&unions).objects.len(), 251);
    let sum = format!("sphere {{ radius 1{} }}", " + 1".repeat(1000));
    scene(&sum);
    // Recursion to the call-depth limit, each level with nested blocks and expressions.
    let recursion = "fn down(n) {\n\
         if n > 0 { if true { for i in 0..1 { let x = ((((n)))) * 1; down(x - 1) } } }\n\
         else { sphere { } }\n\
         }\n\
         down(250)";
    assert_eq!(scene(recursion).objects.len(), 1);
}

#[test]
fn a_loop_of_a_billion_stops_before_it_starts() {
    let start = std::time::Instant::now();
    let message = first_error_of("for i in 0..1000000000 { sphere { } }");
    assert!(
        message.contains(
            "past the evaluation steps limit (100000000 loop iterations and calls in total)"
        ),
        "{message}"
    );
    // Refused up front, not after counting: no timing assertion, but a loop that ran would
    // take minutes in a debug build, and this test would be the slowest in the suite.
    let _ = start;
}

#[test]
fn runaway_recursion_stops_at_the_call_depth_limit() {
    let message = first_error_of("fn f(n) { f(n + 1) }\nf(0)");
    assert!(message.contains("call depth limit (256)"), "{message}");
    let options = CompileOptions {
        limits: Limits {
            max_call_depth: 100_000,
            ..Limits::default()
        },
        ..CompileOptions::default()
    };
    // Even with a huge call-depth limit, the evaluator's own depth bound stops the recursion
    // before the stack runs out.
    let compilation = compile_with(
        "fn f(n) { f(n + 1) }\nf(0)",
        &mut MapLoader::default(),
        &options,
    );
    let error = compilation
        .diagnostics
        .iter()
        .find(|d| d.is_error())
        .expect("an error");
    assert!(
        error
            .message
            .starts_with("the scene nests too deeply while running"),
        "{}",
        error.message
    );
}

#[test]
fn too_many_objects_stop_with_the_object_limit() {
    let options = CompileOptions {
        limits: Limits {
            max_objects: 1000,
            ..Limits::default()
        },
        ..CompileOptions::default()
    };
    let compilation = compile_with(
        "for i in 0..100 { for j in 0..100 { sphere { } } }",
        &mut MapLoader::default(),
        &options,
    );
    let errors: Vec<_> = compilation
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .collect();
    assert_eq!(errors.len(), 1);
    assert!(errors[0].message.contains("objects limit (1000)"));
}

#[test]
fn nan_and_infinity_never_reach_the_ir() {
    for input in [
        "sphere { radius 1e308 * 10 }",
        "sphere { center <1e308, 0, 0> * 10 }",
        "sphere { radius pow(-8, 1 / 3) }",
        "sphere { radius exp(1000) }",
        "sphere { radius 0 / 0 }",
        "let big = 1e200; sphere { radius big * big }",
        "sphere { center normalize(<1e-320, 0, 0>) * 1e308 * 10 }",
    ] {
        let compilation = compile(input);
        assert!(compilation.has_errors(), "{input} compiled");
        assert!(
            compilation.diagnostics.iter().all(|d| d.span.is_some()),
            "{input}"
        );
    }
}

#[test]
fn limits_raised_far_past_the_defaults_still_cannot_overflow_the_stack() {
    let options = CompileOptions {
        limits: Limits {
            max_nesting: 10_000_000,
            max_call_depth: 10_000_000,
            ..Limits::default()
        },
        ..CompileOptions::default()
    };
    for input in [
        format!("let x = {}1{};", "(".repeat(100_000), ")".repeat(100_000)),
        format!("{}{}", "group {".repeat(100_000), "}".repeat(100_000)),
        "fn f(n) { f(n + 1) }\nf(0)".to_string(),
    ] {
        let compilation = compile_with(&input, &mut MapLoader::default(), &options);
        let error = compilation.diagnostics.iter().find(|d| d.is_error());
        assert!(
            error.is_some_and(|e| e.span.is_some()),
            "{:?}",
            compilation.diagnostics
        );
    }
}

#[test]
fn a_priority_is_a_whole_number_within_its_range() {
    let fraction = first_error_of("material m { priority 1.5 }\nsphere { material m }");
    assert!(fraction.contains("whole number"), "{fraction}");
    let huge = first_error_of("material m { priority 1e12 }\nsphere { material m }");
    assert!(huge.contains("priority"), "{huge}");
    let negative = first_error_of("material m { priority -1 }\nsphere { material m }");
    assert!(negative.contains("priority"), "{negative}");
}
