//! Built-in constants and functions. Every angle in the language is in degrees, the trig
//! functions included, so `cos(i * 360 / n)` places things around a circle.
//!
//! Three names are the animation's clock (`frame`, `clock`, `fps`): constants whose values
//! the compilation's [`FrameClock`](crate::FrameClock) gives, not this table.

use whitted_ir::DVec3;

use crate::value::Value;

/// Named constants: `pi` and a few colours (linear RGB).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Constant {
    Pi,
    Black,
    White,
    Gray,
    Grey,
    Red,
    Green,
    Blue,
    Yellow,
    Cyan,
    Magenta,
    /// The frame being compiled.
    Frame,
    /// The frame's place in the animation, 0 at the first frame to 1 at the last.
    Clock,
    /// Frames per second.
    Fps,
}

impl Constant {
    pub const ALL: [Constant; 14] = [
        Constant::Pi,
        Constant::Black,
        Constant::White,
        Constant::Gray,
        Constant::Grey,
        Constant::Red,
        Constant::Green,
        Constant::Blue,
        Constant::Yellow,
        Constant::Cyan,
        Constant::Magenta,
        Constant::Frame,
        Constant::Clock,
        Constant::Fps,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Constant::Pi => "pi",
            Constant::Black => "black",
            Constant::White => "white",
            Constant::Gray => "gray",
            Constant::Grey => "grey",
            Constant::Red => "red",
            Constant::Green => "green",
            Constant::Blue => "blue",
            Constant::Yellow => "yellow",
            Constant::Cyan => "cyan",
            Constant::Magenta => "magenta",
            Constant::Frame => "frame",
            Constant::Clock => "clock",
            Constant::Fps => "fps",
        }
    }

    pub fn from_name(name: &str) -> Option<Constant> {
        Constant::ALL.into_iter().find(|c| c.name() == name)
    }

    /// The constant's value; the clock's three names take theirs from `clock`.
    pub fn value(self, clock: &crate::FrameClock) -> Value {
        let v = |r, g, b| Value::Vector(DVec3::new(r, g, b));
        match self {
            Constant::Frame => Value::Number(f64::from(clock.frame)),
            Constant::Clock => Value::Number(clock.clock()),
            Constant::Fps => Value::Number(f64::from(clock.fps)),
            Constant::Pi => Value::Number(std::f64::consts::PI),
            Constant::Black => v(0.0, 0.0, 0.0),
            Constant::White => v(1.0, 1.0, 1.0),
            Constant::Gray | Constant::Grey => v(0.5, 0.5, 0.5),
            Constant::Red => v(1.0, 0.0, 0.0),
            Constant::Green => v(0.0, 1.0, 0.0),
            Constant::Blue => v(0.0, 0.0, 1.0),
            Constant::Yellow => v(1.0, 1.0, 0.0),
            Constant::Cyan => v(0.0, 1.0, 1.0),
            Constant::Magenta => v(1.0, 0.0, 1.0),
        }
    }

    /// Whether the value is the animation clock's (it changes from frame to frame).
    pub fn is_clock(self) -> bool {
        matches!(self, Constant::Frame | Constant::Clock | Constant::Fps)
    }
}

/// Built-in functions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Function {
    Sqrt,
    Pow,
    Exp,
    Log,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Abs,
    Min,
    Max,
    Floor,
    Ceil,
    Round,
    Clamp,
    Radians,
    Degrees,
    Dot,
    Cross,
    Length,
    Normalize,
    Mix,
    Rgb,
    Srgb,
    Checker,
    Stripes,
    Marble,
    Wood,
    Turbulence,
    Len,
    Rand,
    Lerp,
    Smoothstep,
    Keyframes,
}

impl Function {
    pub const ALL: [Function; 37] = [
        Function::Sqrt,
        Function::Pow,
        Function::Exp,
        Function::Log,
        Function::Sin,
        Function::Cos,
        Function::Tan,
        Function::Asin,
        Function::Acos,
        Function::Atan,
        Function::Atan2,
        Function::Abs,
        Function::Min,
        Function::Max,
        Function::Floor,
        Function::Ceil,
        Function::Round,
        Function::Clamp,
        Function::Radians,
        Function::Degrees,
        Function::Dot,
        Function::Cross,
        Function::Length,
        Function::Normalize,
        Function::Mix,
        Function::Rgb,
        Function::Srgb,
        Function::Checker,
        Function::Stripes,
        Function::Marble,
        Function::Wood,
        Function::Turbulence,
        Function::Len,
        Function::Rand,
        Function::Lerp,
        Function::Smoothstep,
        Function::Keyframes,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Function::Sqrt => "sqrt",
            Function::Pow => "pow",
            Function::Exp => "exp",
            Function::Log => "log",
            Function::Sin => "sin",
            Function::Cos => "cos",
            Function::Tan => "tan",
            Function::Asin => "asin",
            Function::Acos => "acos",
            Function::Atan => "atan",
            Function::Atan2 => "atan2",
            Function::Abs => "abs",
            Function::Min => "min",
            Function::Max => "max",
            Function::Floor => "floor",
            Function::Ceil => "ceil",
            Function::Round => "round",
            Function::Clamp => "clamp",
            Function::Radians => "radians",
            Function::Degrees => "degrees",
            Function::Dot => "dot",
            Function::Cross => "cross",
            Function::Length => "length",
            Function::Normalize => "normalize",
            Function::Mix => "mix",
            Function::Rgb => "rgb",
            Function::Srgb => "srgb",
            Function::Checker => "checker",
            Function::Stripes => "stripes",
            Function::Marble => "marble",
            Function::Wood => "wood",
            Function::Turbulence => "turbulence",
            Function::Len => "len",
            Function::Rand => "rand",
            Function::Lerp => "lerp",
            Function::Smoothstep => "smoothstep",
            Function::Keyframes => "keyframes",
        }
    }

    pub fn from_name(name: &str) -> Option<Function> {
        Function::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The smallest and largest number of arguments.
    pub fn arity(self) -> (usize, usize) {
        use Function::*;
        match self {
            Sqrt | Exp | Log | Sin | Cos | Tan | Asin | Acos | Atan | Abs | Floor | Ceil
            | Round | Radians | Degrees | Length | Normalize | Len => (1, 1),
            Pow | Atan2 | Min | Max | Dot | Cross | Rand | Keyframes => (2, 2),
            Clamp | Mix | Rgb | Srgb | Lerp | Smoothstep => (3, 3),
            Checker | Stripes | Marble | Wood | Turbulence => (2, 3),
        }
    }

    /// How the docs and arity errors show the call.
    pub fn signature(self) -> &'static str {
        use Function::*;
        match self {
            Sqrt => "sqrt(x)",
            Pow => "pow(x, y)",
            Exp => "exp(x)",
            Log => "log(x)",
            Sin => "sin(degrees)",
            Cos => "cos(degrees)",
            Tan => "tan(degrees)",
            Asin => "asin(x)",
            Acos => "acos(x)",
            Atan => "atan(x)",
            Atan2 => "atan2(y, x)",
            Abs => "abs(x)",
            Min => "min(a, b)",
            Max => "max(a, b)",
            Floor => "floor(x)",
            Ceil => "ceil(x)",
            Round => "round(x)",
            Clamp => "clamp(x, low, high)",
            Radians => "radians(degrees)",
            Degrees => "degrees(radians)",
            Dot => "dot(u, v)",
            Cross => "cross(u, v)",
            Length => "length(v)",
            Normalize => "normalize(v)",
            Mix => "mix(a, b, t)",
            Rgb => "rgb(r, g, b)",
            Srgb => "srgb(r, g, b)",
            Checker => "checker(a, b, size)",
            Stripes => "stripes(a, b, width)",
            Marble => "marble(a, b, size)",
            Wood => "wood(a, b, size)",
            Turbulence => "turbulence(a, b, size)",
            Len => "len(array)",
            Rand => "rand(seed, i)",
            Lerp => "lerp(a, b, t)",
            Smoothstep => "smoothstep(edge0, edge1, x)",
            Keyframes => "keyframes([[t0, value0], [t1, value1], ...], t)",
        }
    }
}

/// Sine and cosine of an angle in degrees, exact at multiples of 90 degrees (so that
/// `cos(90)` is 0, not 6e-17, and a quarter turn is an exact quarter turn).
pub fn sin_cos_degrees(degrees: f64) -> (f64, f64) {
    let reduced = degrees.rem_euclid(360.0);
    match reduced {
        0.0 => (0.0, 1.0),
        90.0 => (1.0, 0.0),
        180.0 => (0.0, -1.0),
        270.0 => (-1.0, 0.0),
        _ => reduced.to_radians().sin_cos(),
    }
}

/// Why a built-in call failed; the evaluator turns it into a located diagnostic.
#[derive(Debug, PartialEq)]
pub enum CallError {
    /// Argument `index` has the wrong type; `expected` says what was wanted.
    ArgumentType {
        index: usize,
        expected: &'static str,
    },
    /// The arguments are outside the function's domain (`sqrt(-1)`).
    Domain(String),
}

/// The sRGB transfer function, inverted: an sRGB component in 0..1 to linear light.
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn number(args: &[Value], index: usize) -> Result<f64, CallError> {
    match args.get(index) {
        Some(Value::Number(x)) => Ok(*x),
        _ => Err(CallError::ArgumentType {
            index,
            expected: "a number",
        }),
    }
}

fn vector(args: &[Value], index: usize) -> Result<DVec3, CallError> {
    match args.get(index) {
        Some(Value::Vector(v)) => Ok(*v),
        _ => Err(CallError::ArgumentType {
            index,
            expected: "a vector",
        }),
    }
}

/// Evaluates every built-in except the patterns (which need the evaluator's tables).
/// The caller checks that the result is finite.
pub fn call_math(function: Function, args: &[Value]) -> Result<Value, CallError> {
    use Function::*;
    let n = |i| number(args, i);
    let num = |x: f64| Ok(Value::Number(x));
    match function {
        Sqrt => {
            let x = n(0)?;
            if x < 0.0 {
                return Err(CallError::Domain(format!(
                    "the square root of a negative number ({x})"
                )));
            }
            num(x.sqrt())
        }
        Pow => num(n(0)?.powf(n(1)?)),
        Exp => num(n(0)?.exp()),
        Log => {
            let x = n(0)?;
            if x <= 0.0 {
                return Err(CallError::Domain(format!(
                    "the logarithm of a number that is not positive ({x})"
                )));
            }
            num(x.ln())
        }
        Sin => num(sin_cos_degrees(n(0)?).0),
        Cos => num(sin_cos_degrees(n(0)?).1),
        Tan => {
            let (sin, cos) = sin_cos_degrees(n(0)?);
            if cos == 0.0 {
                return Err(CallError::Domain(
                    "the tangent of 90 degrees (plus a multiple of 180) is infinite".into(),
                ));
            }
            num(sin / cos)
        }
        Asin | Acos => {
            let x = n(0)?;
            if !(-1.0..=1.0).contains(&x) {
                return Err(CallError::Domain(format!(
                    "`{}` needs a number between -1 and 1, not {x}",
                    function.name()
                )));
            }
            let radians = if function == Asin { x.asin() } else { x.acos() };
            num(radians.to_degrees())
        }
        Atan => num(n(0)?.atan().to_degrees()),
        Atan2 => num(n(0)?.atan2(n(1)?).to_degrees()),
        Abs => num(n(0)?.abs()),
        Min => num(n(0)?.min(n(1)?)),
        Max => num(n(0)?.max(n(1)?)),
        Floor => num(n(0)?.floor()),
        Ceil => num(n(0)?.ceil()),
        Round => num(n(0)?.round()),
        Clamp => {
            let (x, low, high) = (n(0)?, n(1)?, n(2)?);
            if low > high {
                return Err(CallError::Domain(format!(
                    "`clamp` needs low <= high, not {low} > {high}"
                )));
            }
            num(x.clamp(low, high))
        }
        Radians => num(n(0)?.to_radians()),
        Degrees => num(n(0)?.to_degrees()),
        Dot => num(vector(args, 0)?.dot(vector(args, 1)?)),
        Cross => Ok(Value::Vector(vector(args, 0)?.cross(vector(args, 1)?))),
        Length => num(vector(args, 0)?.length()),
        Normalize => {
            let v = vector(args, 0)?;
            if v.length() == 0.0 {
                return Err(CallError::Domain(
                    "a zero-length vector has no direction to normalize".into(),
                ));
            }
            Ok(Value::Vector(v.normalize()))
        }
        Smoothstep => {
            let (e0, e1, x) = (n(0)?, n(1)?, n(2)?);
            if e0 == e1 {
                return Err(CallError::Domain(format!(
                    "`smoothstep` needs two different edges, not {e0} twice"
                )));
            }
            let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
            num(t * t * (3.0 - 2.0 * t))
        }
        Mix | Lerp => {
            let t = n(2)?;
            match (args.first(), args.get(1)) {
                (Some(Value::Number(a)), Some(Value::Number(b))) => num(a + (b - a) * t),
                (Some(Value::Vector(a)), Some(Value::Vector(b))) => {
                    Ok(Value::Vector(*a + (*b - *a) * t))
                }
                (Some(Value::Number(_)), _) => Err(CallError::ArgumentType {
                    index: 1,
                    expected: "a number, like the first argument",
                }),
                (Some(Value::Vector(_)), _) => Err(CallError::ArgumentType {
                    index: 1,
                    expected: "a vector, like the first argument",
                }),
                _ => Err(CallError::ArgumentType {
                    index: 0,
                    expected: "a number or a vector",
                }),
            }
        }
        Rgb => Ok(Value::Vector(DVec3::new(n(0)?, n(1)?, n(2)?))),
        Srgb => Ok(Value::Vector(DVec3::new(
            srgb_to_linear(n(0)?),
            srgb_to_linear(n(1)?),
            srgb_to_linear(n(2)?),
        ))),
        Rand => num(crate::random::rand(n(0)?, n(1)?)),
        Checker | Stripes | Marble | Wood | Turbulence | Len | Keyframes => Err(CallError::Domain(
            "patterns, `len` and `keyframes` are evaluated by the evaluator".into(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn call(f: Function, args: &[Value]) -> Value {
        match call_math(f, args) {
            Ok(v) => v,
            Err(e) => panic!("{f:?} failed: {e:?}"),
        }
    }

    #[test]
    fn trig_works_in_degrees() {
        let Value::Number(c) = call(Function::Cos, &[Value::Number(60.0)]) else {
            panic!("not a number")
        };
        assert!((c - 0.5).abs() < 1e-12);
        let Value::Number(a) = call(Function::Atan2, &[Value::Number(1.0), Value::Number(1.0)])
        else {
            panic!("not a number")
        };
        assert!((a - 45.0).abs() < 1e-12);
    }

    #[test]
    fn domain_and_type_errors_are_reported_not_computed() {
        assert!(matches!(
            call_math(Function::Sqrt, &[Value::Number(-1.0)]),
            Err(CallError::Domain(_))
        ));
        assert_eq!(
            call_math(Function::Length, &[Value::Number(1.0)]),
            Err(CallError::ArgumentType {
                index: 0,
                expected: "a vector"
            })
        );
    }

    #[test]
    fn quarter_turns_are_exact() {
        assert_eq!(sin_cos_degrees(90.0), (1.0, 0.0));
        assert_eq!(sin_cos_degrees(-90.0), (-1.0, 0.0));
        assert_eq!(sin_cos_degrees(540.0), (0.0, -1.0));
        let (s, c) = sin_cos_degrees(30.0);
        assert!((s - 0.5).abs() < 1e-15 && (c - 0.75f64.sqrt()).abs() < 1e-15);
        assert!(matches!(
            call_math(Function::Tan, &[Value::Number(90.0)]),
            Err(CallError::Domain(_))
        ));
    }

    #[test]
    fn srgb_mid_grey_is_about_a_fifth_in_linear_light() {
        assert!((srgb_to_linear(0.5) - 0.214).abs() < 1e-3);
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn names_round_trip() {
        for f in Function::ALL {
            assert_eq!(Function::from_name(f.name()), Some(f));
            let (low, high) = f.arity();
            assert!(low <= high);
        }
        for c in Constant::ALL {
            assert_eq!(Constant::from_name(c.name()), Some(c));
        }
    }
}
