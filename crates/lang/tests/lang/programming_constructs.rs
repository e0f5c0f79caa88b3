//! The language's programming constructs (added in issue 15): arrays and indexing, `for ...
//! step`, `while` and assignment, `rand`, formatted strings and expression-bodied functions.
//! Values are checked against oracles written here (a `Vec`, a formula, a hash by hand).

use whitted_ir::Shape;
use whitted_lang::{CompileOptions, Limits};

use crate::support::*;

/// The x of every sphere centre, in order.
fn xs(input: &str) -> Vec<f64> {
    let scene = scene(input);
    scene
        .objects
        .iter()
        .filter_map(|(_, o)| match o.kind.shape() {
            Some(Shape::Sphere { center, .. }) => Some(center.x),
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
        .filter_map(|(_, o)| scene.name_of(o).map(str::to_string))
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

/// A small deterministic generator for test inputs (not the code under test).
struct Lcg(u64);

impl Lcg {
    fn below(&mut self, n: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) % n
    }
}

fn with_steps(steps: u64) -> CompileOptions {
    CompileOptions {
        limits: Limits {
            max_evaluation_steps: steps,
            ..Limits::default()
        },
        ..CompileOptions::default()
    }
}

// ---- arrays --------------------------------------------------------------------------------

#[test]
fn indexing_matches_a_vec_for_generated_arrays_and_indices() {
    let mut rng = Lcg(15);
    for case in 0..200 {
        let len = rng.below(7) as usize;
        let values: Vec<f64> = (0..len).map(|_| rng.below(1000) as f64 / 8.0).collect();
        // Indices in and out of range, negative, and some with a fraction.
        let index = rng.below(len as u64 + 6) as f64 - 3.0 + if case % 7 == 0 { 0.5 } else { 0.0 };
        let list: Vec<String> = values.iter().map(|v| v.to_string()).collect();
        let input = format!(
            "let a = [{}];\nsphere {{ center <a[{index}], 0, 0> }}\n",
            list.join(", ")
        );
        let compilation = compile(&input);
        let in_range = index.fract() == 0.0 && index >= 0.0 && (index as usize) < len;
        if in_range {
            assert_eq!(xs(&input), vec![values[index as usize]], "{input}");
            continue;
        }
        let text = output(&compilation);
        assert!(compilation.scene.is_none(), "{input}");
        let expected = if index.fract() != 0.0 {
            format!("an array index must be a whole number, not {index}")
        } else {
            format!("index {index} is out of range for an array of length {len}")
        };
        assert!(text.contains(&expected), "{input}\n{text}");
        // The place: the index, on line 2.
        let column = input.lines().nth(1).and_then(|l| l.find("a[")).unwrap_or(0) + 3;
        assert!(
            text.contains(&format!("test.scene:2:{column}")),
            "{input}\n{text}"
        );
    }
}

#[test]
fn arrays_hold_any_value_and_nest() {
    let scene = scene(
        "let ms = [material { diffuse red }, material { diffuse blue }];\n\
         let vs = [<1, 0, 0>, <2, 0, 0>];\n\
         let ns = [\"left\", \"right\"];\n\
         for i in 0..2 { let n = ns[i]; sphere \"{n}\" { center vs[i] material ms[i] } }",
    );
    let names: Vec<_> = scene
        .objects
        .iter()
        .filter_map(|(_, o)| scene.name_of(o))
        .collect();
    assert_eq!(names, ["left", "right"]);
    assert_eq!(
        xs("let a = [[1, 2], [3, [4, 5]]];\nsphere { center <a[1][1][0], 0, 0> }"),
        [4.0]
    );
    assert_eq!(
        xs("let a = [1, 2, 3,];\nsphere { center <len(a), len([]), len(\"abc\")> }"),
        [3.0]
    );
    assert!(boolean("[1, \"a\"] == [1, \"a\"]"));
    assert!(boolean("[1, 2] != [1, 3]"));
    assert!(boolean("[[1]] != [[1], 2]"));
    assert!(boolean("\"ab\" == \"ab\" && \"ab\" != \"b\""));
}

#[test]
fn colours_cycle_through_an_array() {
    // The issue's own example.
    let scene = scene(
        "let colours = [red, blue];\n\
         for i in 0..4 { sphere { center <i, 0, 0> material { diffuse colours[i % 2] } } }",
    );
    let diffuse: Vec<_> = scene
        .objects
        .iter()
        .map(|(_, o)| {
            let diffuse = scene.materials[o.material].diffuse;
            (diffuse.r, diffuse.b)
        })
        .collect();
    assert_eq!(diffuse, [(1.0, 0.0), (0.0, 1.0), (1.0, 0.0), (0.0, 1.0)]);
}

#[test]
fn a_nest_a_million_deep_compares_without_recursion() {
    let compilation = compile_with(
        "let a = [0];\nlet b = [0];\nfor i in 0..200000 { a = [a]; b = [b]; }\nif a == b { sphere { } }\n",
        &mut MapLoader::default(),
        &CompileOptions::default(),
    );
    assert!(compilation.scene.is_some(), "{}", output(&compilation));
}

// ---- loops ---------------------------------------------------------------------------------

#[test]
fn stepped_loops_match_a_counting_oracle() {
    let mut rng = Lcg(2);
    for _ in 0..150 {
        let a = rng.below(21) as i64 - 10;
        let b = rng.below(21) as i64 - 10;
        let s = (rng.below(4) as i64 + 1) * if rng.below(2) == 0 { 1 } else { -1 };
        let inclusive = rng.below(2) == 0;
        let mut expected = Vec::new();
        let mut i = a;
        while (s > 0 && (i < b || (inclusive && i == b)))
            || (s < 0 && (i > b || (inclusive && i == b)))
        {
            expected.push(i as f64);
            i += s;
        }
        let op = if inclusive { "..=" } else { ".." };
        let input = format!(
            "for i in {a}{op}{b} step {s} {{ sphere {{ center <i, 0, 0> }} }}\nsphere {{ center <99, 0, 0> }}"
        );
        expected.push(99.0);
        assert_eq!(xs(&input), expected, "{input}");
    }
}

#[test]
fn a_stepped_loop_counts_its_iterations_against_the_budget() {
    let input = "for i in 0..100 step 2 { }\nsphere { }\n";
    let fits = compile_with(input, &mut MapLoader::default(), &with_steps(50));
    assert!(fits.scene.is_some(), "{}", output(&fits));
    let over = compile_with(input, &mut MapLoader::default(), &with_steps(49));
    assert!(
        output(&over).contains("this loop would run 50 times"),
        "{}",
        output(&over)
    );
}

#[test]
fn while_loops_and_assignment() {
    // Powers of two below 100, by doubling.
    assert_eq!(
        xs("let x = 1;\nwhile x < 100 { sphere { center <x, 0, 0> } x = x * 2; }"),
        [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0]
    );
    // Inside a function, on its own `let`, with a `return` from the loop.
    assert_eq!(
        xs("fn first_square_over(n) { let i = 0; while true { if i * i > n { return i; } i = i + 1; } }\n\
            sphere { center <first_square_over(50), 0, 0> }"),
        [8.0]
    );
    // Every iteration is a step: 10 iterations fit in 10 steps, not in 9.
    let input = "let i = 0;\nwhile i < 10 { i = i + 1; }\nsphere { }\n";
    assert!(
        compile_with(input, &mut MapLoader::default(), &with_steps(10))
            .scene
            .is_some()
    );
    let over = compile_with(input, &mut MapLoader::default(), &with_steps(9));
    assert!(
        output(&over).contains("reached the evaluation steps limit (9 "),
        "{}",
        output(&over)
    );
}

// ---- rand ----------------------------------------------------------------------------------

/// The hash `rand` documents, written out again from its definition: SplitMix64's
/// finaliser over the bits of the seed (plus the golden-ratio constant), xor the bits of i,
/// finalised again, top 53 bits over 2^53.
fn rand_by_hand(seed: f64, i: f64) -> f64 {
    fn fin(z: u64) -> u64 {
        let z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        let z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^ (z >> 31)
    }
    let bits = |x: f64| if x == 0.0 { 0 } else { x.to_bits() };
    let h = fin(fin(bits(seed).wrapping_add(0x9E3779B97F4A7C15)) ^ bits(i));
    (h >> 11) as f64 / 9_007_199_254_740_992.0
}

#[test]
fn rand_is_the_documented_hash_and_stays_in_range() {
    let cases = [
        (0.0, 0.0),
        (1.0, 2.0),
        (7.0, 3.0),
        (-1.0, 1e6),
        (0.5, -0.0),
        (42.0, 99.0),
    ];
    for (seed, i) in cases {
        let got = number(&format!("rand({seed}, {i})"));
        assert_eq!(got, rand_by_hand(seed, i), "rand({seed}, {i})");
        assert!((0.0..1.0).contains(&got));
    }
    // -0 and 0 are the same number.
    assert_eq!(number("rand(0, -0)"), number("rand(0, 0)"));
    // Fixed values, computed outside Rust (Python, with the same formula): these must never
    // change between platforms or versions, or every scene that uses `rand` would move.
    assert_eq!(number("rand(0, 0)"), 0.28176129772258496);
    assert_eq!(number("rand(1, 2)"), 0.18468589248590483);
    assert_eq!(number("rand(7, 3)"), 0.5598742681448604);
    assert_eq!(number("rand(42, 99)"), 0.4743535653865202);
}

#[test]
fn rand_is_roughly_uniform() {
    // 4,000 values in 10 bins: each bin expects 400; a uniform source stays well inside
    // 400 +- 100 (more than 5 standard deviations).
    let scene = scene("for i in 0..4000 { sphere { center <rand(3, i), 0, 0> radius 0.1 } }");
    let mut bins = [0usize; 10];
    for (_, object) in scene.objects.iter() {
        if let Some(Shape::Sphere { center, .. }) = object.kind.shape() {
            bins[(center.x * 10.0) as usize] += 1;
        }
    }
    for count in bins {
        assert!((300..=500).contains(&count), "{bins:?}");
    }
}

// ---- strings -------------------------------------------------------------------------------

#[test]
fn names_are_formatted_from_their_holes() {
    assert_eq!(
        names("for i in 0..3 { sphere \"ball {i}\" { } }"),
        ["ball 0", "ball 1", "ball 2"]
    );
    assert_eq!(
        names("let name = \"ball\";\nlet v = <1, 0.5, -2>;\nlet b = 1 < 2;\nsphere \"{name}: {v} {b} {{x}}\" { }"),
        ["ball: <1, 0.5, -2> true {x}"]
    );
    assert_eq!(
        names("let x = -0;\nsphere \"\\\"{x}\\\"\\t\" { }"),
        ["\"0\"\t"]
    );
    let scene = scene("let n = 2;\nlight point \"lamp {n}\" { position <0, 5, 0> }");
    let light_names: Vec<_> = scene
        .lights
        .iter()
        .filter_map(|(_, l)| l.name.clone())
        .collect();
    assert_eq!(light_names, ["lamp 2"]);
}

// ---- expression-bodied functions -------------------------------------------------------------

#[test]
fn expression_functions_are_values() {
    assert_eq!(
        xs("fn square(x) = x * x;\nfn hyp(a, b) = sqrt(square(a) + square(b));\nsphere { center <hyp(3, 4), square(2), 0> }"),
        [5.0]
    );
    // Recursion is bounded by the call depth limit, as for block functions.
    let text = errors("fn f(n) = f(n - 1) + 1;\nsphere { radius f(3) }\n");
    assert!(
        text.contains("the call depth limit (256) was reached"),
        "{text}"
    );
}

// ---- errors ----------------------------------------------------------------------------------

#[test]
fn programming_construct_errors() {
    check_errors(
        "programming_construct_errors",
        &[
            (
                "an index out of range",
                "let a = [1, 2];\nsphere { radius a[2] }\n",
            ),
            (
                "a negative index",
                "let a = [1, 2];\nsphere { radius a[-1] }\n",
            ),
            (
                "an index with a fraction",
                "let a = [1, 2];\nsphere { radius a[0.5] }\n",
            ),
            (
                "an index into an empty array",
                "let a = [];\nsphere { radius a[0] }\n",
            ),
            (
                "indexing a vector",
                "let v = <1, 2, 3>;\nsphere { radius v[0] }\n",
            ),
            ("indexing a number", "let n = 3;\nsphere { radius n[0] }\n"),
            (
                "an index that is not a number",
                "let a = [1];\nsphere { radius a[true] }\n",
            ),
            ("len of a number", "sphere { radius len(3) }\n"),
            ("an array as a property value", "sphere { radius [1, 2] }\n"),
            ("a step of zero", "for i in 0..3 step 0 { }\n"),
            ("a step with a fraction", "for i in 0..3 step 0.5 { }\n"),
            ("a step over the budget", "for i in 0..1e12 step 2 { }\n"),
            ("a while condition that is not a boolean", "while 1 { }\n"),
            ("assigning a constant", "const k = 1;\nk = 2;\n"),
            ("assigning a loop variable", "for i in 0..3 { i = 2; }\n"),
            (
                "assigning a parameter",
                "fn f(n) { n = 2; return n; }\nsphere { radius f(1) }\n",
            ),
            (
                "assigning outside a function",
                "let total = 0;\nfn add(n) { total = total + n; }\nadd(1)\n",
            ),
            ("assigning an unknown name", "let count = 0;\ncuont = 1;\n"),
            (
                "rand with a vector",
                "sphere { radius rand(<1, 2, 3>, 1) }\n",
            ),
            ("a `{` without a name", "sphere \"ball {i + 1}\" { }\n"),
            ("a `{` never closed", "let s = \"ball {\";\n"),
            ("a lone `}`", "sphere \"ball }\" { }\n"),
            ("an unknown name in a string", "sphere \"ball {j}\" { }\n"),
            ("an array in a string", "let a = [1];\nsphere \"{a}\" { }\n"),
            (
                "a string over the length limit",
                // 64 bytes, 512, 4,096, then one more.
                "let a = \"xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx\";\n\
                 let b = \"{a}{a}{a}{a}{a}{a}{a}{a}\";\nlet c = \"{b}{b}{b}{b}{b}{b}{b}{b}\";\n\
                 sphere \"{c}\" { }\nsphere \"{c}!\" { }\n",
            ),
            ("a string as a number", "sphere { radius \"1\" }\n"),
            (
                "an object name without braces",
                "sphere \"ball\"\nbox { }\n",
            ),
            (
                "a block function that is one expression",
                "fn f(x) { x * x }\nsphere { radius f(2) }\n",
            ),
        ],
    );
}

#[test]
fn the_while_budget_error_names_the_limit() {
    let compilation = compile_with(
        "let i = 0;\nwhile i < 1 { }\n",
        &mut MapLoader::default(),
        &with_steps(1000),
    );
    insta::with_settings!({ prepend_module_to_snapshot => false }, {
        insta::assert_snapshot!("while_budget", output(&compilation));
    });
}

/// Broken uses of the new syntax, generated: none may panic, each must be an error.
#[test]
fn malformed_constructs_are_errors_not_panics() {
    let pieces = [
        "[",
        "]",
        "[1, 2]",
        "a[",
        "a[0]",
        "step",
        "step 0",
        "while",
        "while true",
        "{",
        "}",
        "\"{\"",
        "\"}\"",
        "\"{i}\"",
        "\"{{\"",
        "=",
        "i = ",
        ";",
        "fn g(x) =",
        "len(",
        "rand(",
        "..",
        "for i in 0..3",
        "let a = ",
        "sphere",
        "1",
        "<1, 2, 3>",
        ",",
    ];
    let mut rng = Lcg(9);
    for _ in 0..400 {
        let mut input = String::from("let a = [1, 2];\nlet i = 0;\n");
        for _ in 0..1 + rng.below(6) {
            input.push_str(pieces[rng.below(pieces.len() as u64) as usize]);
            input.push(' ');
        }
        let compilation = compile_with(&input, &mut MapLoader::default(), &with_steps(10_000));
        // Either it compiled, or every problem is a located diagnostic.
        if compilation.scene.is_none() {
            assert!(
                compilation
                    .diagnostics
                    .iter()
                    .any(|d| d.is_error() && d.span.is_some()),
                "{input}\n{}",
                output(&compilation)
            );
        }
    }
}

#[test]
fn arrays_made_in_a_loop_stop_at_the_value_memory_limit() {
    // 1,000 elements of 32 bytes a time: the 256 MiB limit is reached after about 8,000
    // iterations, long before the loop's 100,000.
    let zeros = vec!["0"; 1000].join(", ");
    let input = format!("for i in 0..100000 {{ let a = [{zeros}]; }}\n");
    let text = errors(&input);
    assert!(
        text.contains("the value memory limit (268435456 bytes of arrays and strings) was reached"),
        "{text}"
    );
    assert!(text.contains("test.scene:1:30"), "{text}");
}

#[test]
fn an_array_over_the_length_limit_is_an_error() {
    let over = whitted_ir::limits::MAX_ARRAY_LENGTH + 1;
    let input = format!("let a = [{}];\n", vec!["0"; over].join(","));
    let text = errors(&input);
    assert!(
        text.contains(&format!(
            "this array has {over} elements, past the array length limit"
        )),
        "{}",
        &text[..text.len().min(300)]
    );
}

#[test]
fn empty_arrays_made_in_a_loop_are_not_free() {
    // Each empty array still keeps a header (24 bytes), so 20 million of them pass the
    // 256 MiB limit. Charged by their elements alone, they cost nothing and the loop held
    // 480 MB when it ended.
    let text = errors("for i in 0..20000000 { let a = []; }\n");
    assert!(text.contains("the value memory limit"), "{text}");
}
