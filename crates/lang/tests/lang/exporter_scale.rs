//! Scenes written by programs (issue 17): a script printing 100,000 literal statements must
//! cost about twice what 50,000 cost. Time is too noisy to test, so the work is counted
//! deterministically ([`whitted_lang::WorkCounts`]): the fast reader's rule entries and the
//! resolver's name probes. Each scene is compiled at N and 2N statements; doubling may cost
//! at most a little over double.

use whitted_lang::WorkCounts;

use crate::support::*;

const HEADER: &str = "camera perspective { eye <0, 5, -30> look_at <0, 0, 0> }\n\
                      light point { position <10, 20, -10> color <1, 1, 1> }\n";

/// What a script writes: one literal statement per object, with a material of its own every
/// tenth object and a formatted name.
fn literal_spheres(n: usize) -> String {
    let mut text = String::from(HEADER);
    for i in 0..n {
        if i % 10 == 0 {
            text.push_str(&format!(
                "material m{i} {{ diffuse <{}, 0.5, 0.25> }}\n",
                (i % 7) as f64 / 7.0
            ));
        }
        text.push_str(&format!(
            "sphere \"ball {i}\" {{ center <{}.5, -{}, 0.{}> radius 0.25 material m{} }}\n",
            i % 97,
            i % 89,
            i % 83,
            i - i % 10
        ));
    }
    text
}

/// Top-level names, each used by the next (a table of values exported as `let`s).
fn top_level_lets(n: usize) -> String {
    let mut text = String::from(HEADER);
    text.push_str("let v0 = 1;\n");
    for i in 1..n {
        text.push_str(&format!("let v{i} = v{} * 0.5 + {i};\n", i - 1));
    }
    text.push_str(&format!("sphere {{ radius v{} / v{} }}\n", n - 1, n - 1));
    text
}

fn work(text: &str) -> WorkCounts {
    let compilation = compile(text);
    assert!(
        !compilation.has_errors(),
        "{}",
        output(&compilation)
            .lines()
            .take(20)
            .collect::<Vec<_>>()
            .join("\n")
    );
    compilation.work
}

/// `measure(2N) <= ratio * measure(N)`, with both measures named in the failure.
fn at_most_doubles(what: &str, measure: &str, small: u64, large: u64, ratio: f64) {
    assert!(small > 0, "{what}: no {measure} counted at all");
    let grown = large as f64 / small as f64;
    assert!(
        grown <= ratio,
        "{what}: {measure} grew {grown:.2}x from N to 2N ({small} -> {large}); at most {ratio}x"
    );
}

#[test]
fn doubling_literal_statements_at_most_doubles_the_work() {
    let small = work(&literal_spheres(5_000));
    let large = work(&literal_spheres(10_000));
    at_most_doubles(
        "literal spheres",
        "parse steps",
        small.parse_steps,
        large.parse_steps,
        2.05,
    );
    at_most_doubles(
        "literal spheres",
        "name probes",
        small.name_probes,
        large.name_probes,
        2.05,
    );
}

#[test]
fn doubling_top_level_names_at_most_doubles_the_work() {
    let small = work(&top_level_lets(10_000));
    let large = work(&top_level_lets(20_000));
    at_most_doubles(
        "top-level lets",
        "parse steps",
        small.parse_steps,
        large.parse_steps,
        2.05,
    );
    at_most_doubles(
        "top-level lets",
        "name probes",
        small.name_probes,
        large.name_probes,
        2.05,
    );
}

#[test]
fn a_string_where_an_object_body_was_expected_names_the_property() {
    check_errors(
        "exporter_string_property",
        &[
            (
                "a string after an unknown property",
                "sphere { foo \"x\" }\n",
            ),
            (
                "the same between known properties",
                "sphere { radius 1 foo \"x\" center <0, 0, 0> }\n",
            ),
            (
                "in a light",
                "light point { bar \"y\" position <0, 1, 0> }\n",
            ),
        ],
    );
}
