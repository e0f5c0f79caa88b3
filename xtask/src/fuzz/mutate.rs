//! Mutations of valid scenes: numbers swapped for edge values, statements repeated or
//! dropped, tokens inserted, bytes changed. A mutated scene usually still compiles, so the
//! tracer sees values that no hand-written test thought of.

use super::generate::scene;
use super::rng::Rng;

const NUMBERS: &[&str] = &[
    "0", "-0", "1e19", "-1e19", "1e-30", "1e39", "1e308", "3.4e38", "1e-45", "1e-300", "16777217",
    "0.5", "-1", "1000", "65536", "4096",
];

const TOKENS: &[&str] = &[
    "{",
    "}",
    "<",
    ">",
    ",",
    "sphere { }",
    "union { sphere { } box { } }",
    "group {",
    "for i in 0..100 {",
    "rotate <0, 90, 0>",
    "scale 1e-30",
    "scale 1e19",
    "translate <1e19, 0, 0>",
    "material { transmissive 1 ior 1 }",
    "light directional { direction <0, -1, 0> }",
    "settings { shadows filtered }",
    "-",
    "0 / 0",
    "\n",
    "\"",
    "[",
    "]",
    "[1, 2][",
    "step -1",
    "while true {",
    "\"{i}\"",
    "\"{",
    "i = i + 1;",
];

/// Byte offsets of the numbers in `text` (runs of digits with `.` and `e`).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_'));
        if starts {
            let start = i;
            while i < bytes.len()
                && (bytes[i].is_ascii_digit() || bytes[i] == b'.' || bytes[i] == b'e')
            {
                i += 1;
            }
            spans.push((start, i));
        } else {
            i += 1;
        }
    }
    spans
}

/// `text` with one to six mutations.
pub fn mutate(rng: &mut Rng, text: &str) -> String {
    let mut text = text.to_string();
    for _ in 0..1 + rng.below(6) {
        text = mutate_once(rng, &text);
    }
    text
}

fn char_boundary(text: &str, mut at: usize) -> usize {
    at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    at
}

fn mutate_once(rng: &mut Rng, text: &str) -> String {
    let len = text.len().max(1);
    match rng.below(10) {
        0..=4 => {
            let spans = numbers(text);
            if spans.is_empty() {
                return text.to_string();
            }
            let (start, end) = spans[rng.below(spans.len())];
            format!("{}{}{}", &text[..start], rng.pick(NUMBERS), &text[end..])
        }
        5 => {
            let at = char_boundary(text, rng.below(len + 1));
            format!("{} {} {}", &text[..at], rng.pick(TOKENS), &text[at..])
        }
        6 => {
            // Repeat a line many times (many lights, many coincident objects).
            let lines: Vec<&str> = text.lines().collect();
            if lines.is_empty() {
                return text.to_string();
            }
            let pick = rng.below(lines.len());
            let times = *rng.pick(&[2usize, 10, 50]);
            let mut out = String::new();
            for (i, line) in lines.iter().enumerate() {
                out.push_str(line);
                out.push('\n');
                if i == pick {
                    for _ in 0..times {
                        out.push_str(line);
                        out.push('\n');
                    }
                }
            }
            out
        }
        7 => {
            let at = char_boundary(text, rng.below(len));
            let end = char_boundary(text, at + 1 + rng.below(40));
            format!("{}{}", &text[..at], &text[end..])
        }
        8 => format!("{text}\n{}", scene(rng)),
        _ => {
            let mut bytes = text.as_bytes().to_vec();
            if !bytes.is_empty() {
                let at = rng.below(bytes.len());
                bytes[at] = rng.next_u64() as u8;
            }
            String::from_utf8_lossy(&bytes).into_owned()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_found_but_not_inside_names() {
        let text = "sphere { radius 1.5 center <0, 2e3, 10> } let m2 = 4;";
        let found: Vec<&str> = numbers(text).iter().map(|&(s, e)| &text[s..e]).collect();
        assert_eq!(found, ["1.5", "0", "2e3", "10", "4"]);
    }
}
