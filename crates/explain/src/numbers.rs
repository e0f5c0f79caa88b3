//! Numbers as explanations print them: the shortest text that reads back as the same f32,
//! and suggested values rounded to two significant digits (up or down, on the side that
//! keeps the advice true), so that a fix never says `0.030000001`.

/// The shortest text that parses back to `value` (Rust's own shortest round trip), in
/// scientific notation below 0.001 and from 1e7, where decimals would be long.
pub fn shortest(value: f32) -> String {
    let magnitude = value.abs();
    if value != 0.0 && !(1e-3..1e7).contains(&magnitude) {
        format!("{value:e}")
    } else {
        format!("{value}")
    }
}

/// `value` rounded up to two significant digits, as the shortest text of that number: a
/// suggested bound that is at least `value`.
pub fn shortest_up(value: f32) -> String {
    two_digits(value, f64::ceil)
}

/// `value` rounded down to two significant digits: a suggested limit that is at most
/// `value`.
pub fn shortest_down(value: f32) -> String {
    two_digits(value, f64::floor)
}

fn two_digits(value: f32, round: fn(f64) -> f64) -> String {
    // From the f32's shortest decimal, so that 0.095 (stored as 0.0949999988) is 95
    // thousandths and not 94.
    let v: f64 = shortest(value).parse().unwrap_or(f64::from(value));
    if !(v.is_finite() && v > 0.0) {
        return shortest(value);
    }
    let exponent = v.log10().floor() as i32;
    // Two digits: the mantissa in [10, 100); a mantissa within rounding of a whole number
    // is that number.
    let scaled = v / 10f64.powi(exponent - 1);
    let mut mantissa = if (scaled - scaled.round()).abs() < 1e-9 * scaled {
        scaled.round()
    } else {
        round(scaled)
    };
    let mut exponent = exponent;
    if mantissa >= 100.0 {
        mantissa /= 10.0;
        exponent += 1;
    }
    if mantissa < 10.0 {
        mantissa *= 10.0;
        exponent -= 1;
    }
    let digits = mantissa as u32;
    let (whole, tenth) = (digits / 10, digits % 10);
    let scientific = |e: i32| {
        if tenth == 0 {
            format!("{whole}e{e}")
        } else {
            format!("{whole}.{tenth}e{e}")
        }
    };
    if !(-3..7).contains(&exponent) {
        return scientific(exponent);
    }
    // A decimal with just the digits it needs.
    let decimals = (1 - exponent).max(0) as usize;
    let text = format!(
        "{:.*}",
        decimals,
        f64::from(digits) * 10f64.powi(exponent - 1)
    );
    if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggested_values_have_two_digits_on_the_right_side() {
        assert_eq!(shortest_down(0.3 / 10.0), "0.03");
        assert_eq!(shortest_up(0.0014237), "0.0015");
        assert_eq!(shortest_up(1.4237e-5), "1.5e-5");
        assert_eq!(shortest_down(1.4237e-5), "1.4e-5");
        assert_eq!(shortest_up(99.5), "100");
        assert_eq!(shortest_up(2.0), "2");
        assert_eq!(shortest_up(123456.0), "130000");
        assert_eq!(shortest_down(0.001), "0.001");
        assert_eq!(shortest_down(0.95 / 10.0), "0.095");
        for value in [3e-7f32, 0.0123, 0.5, 7.77, 4321.0, 2.5e8] {
            let up: f32 = shortest_up(value).parse().unwrap();
            let down: f32 = shortest_down(value).parse().unwrap();
            assert!(down <= value && value <= up, "{down} <= {value} <= {up}");
        }
    }

    #[test]
    fn shortest_reads_back_as_the_same_number() {
        for value in [0.03f32, 0.3 / 10.0, 5e-4, 1.7, 123.456, 3e9, -2.5e-6] {
            assert_eq!(shortest(value).parse::<f32>().unwrap(), value);
        }
        assert_eq!(shortest(5e-4), "5e-4");
        assert_eq!(shortest(0.25), "0.25");
    }
}
