//! Deterministic gradient noise (Perlin's construction) and the noise patterns built on it:
//! marble, wood and turbulence. The same point gives the same value on every run, thread and
//! machine: the permutation is computed at compile time from a fixed seed.
//!
//! `noise` is 0 at every lattice point and varies smoothly between them (quintic fade), with
//! values in about [-1, 1]; `turbulence` adds four octaves of its absolute value.

/// The lattice's hash: a shuffle of 0..=255 by a fixed xorshift sequence.
const PERMUTATION: [u8; 256] = permutation();

const fn permutation() -> [u8; 256] {
    let mut p = [0u8; 256];
    let mut i = 0;
    while i < 256 {
        p[i] = i as u8;
        i += 1;
    }
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut i = 255;
    while i > 0 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let j = (state % (i as u64 + 1)) as usize;
        let swap = p[i];
        p[i] = p[j];
        p[j] = swap;
        i -= 1;
    }
    p
}

fn hash(i: i32) -> usize {
    PERMUTATION[(i & 255) as usize] as usize
}

/// The dot product of one of the twelve cube-edge gradients (picked by `h`) with `(x, y, z)`.
fn gradient(h: usize, x: f32, y: f32, z: f32) -> f32 {
    match h % 12 {
        0 => x + y,
        1 => -x + y,
        2 => x - y,
        3 => -x - y,
        4 => x + z,
        5 => -x + z,
        6 => x - z,
        7 => -x - z,
        8 => y + z,
        9 => -y + z,
        10 => y - z,
        _ => -y - z,
    }
}

fn fade(t: f32) -> f32 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

fn lerp(t: f32, a: f32, b: f32) -> f32 {
    a + t * (b - a)
}

/// Gradient noise at a point: 0 on the integer lattice, smooth, about within [-1, 1].
pub fn noise(x: f32, y: f32, z: f32) -> f32 {
    // Points beyond the f32 integers have no fraction left: noise is 0 there, as on the
    // lattice. (NaN also lands here, as 0.)
    if !(x.abs() < 8.0e6 && y.abs() < 8.0e6 && z.abs() < 8.0e6) {
        return 0.0;
    }
    let (fx, fy, fz) = (x.floor(), y.floor(), z.floor());
    let (ix, iy, iz) = (fx as i32, fy as i32, fz as i32);
    let (x, y, z) = (x - fx, y - fy, z - fz);
    let (u, v, w) = (fade(x), fade(y), fade(z));
    let corner = |dx: i32, dy: i32, dz: i32| {
        let h = hash(ix + dx + hash(iy + dy + hash(iz + dz) as i32) as i32);
        gradient(h, x - dx as f32, y - dy as f32, z - dz as f32)
    };
    lerp(
        w,
        lerp(
            v,
            lerp(u, corner(0, 0, 0), corner(1, 0, 0)),
            lerp(u, corner(0, 1, 0), corner(1, 1, 0)),
        ),
        lerp(
            v,
            lerp(u, corner(0, 0, 1), corner(1, 0, 1)),
            lerp(u, corner(0, 1, 1), corner(1, 1, 1)),
        ),
    )
}

/// Four octaves of `|noise|`, each twice the frequency and half the weight of the last.
pub fn turbulence(x: f32, y: f32, z: f32) -> f32 {
    let mut sum = 0.0;
    let mut scale = 1.0;
    for _ in 0..4 {
        sum += noise(x * scale, y * scale, z * scale).abs() / scale;
        scale *= 2.0;
    }
    sum
}

/// Four octaves of signed noise (fractal Brownian motion), symmetric about 0.
fn fbm(x: f32, y: f32, z: f32) -> f32 {
    let mut sum = 0.0;
    let mut scale = 1.0;
    for _ in 0..4 {
        sum += noise(x * scale, y * scale, z * scale) / scale;
        scale *= 2.0;
    }
    sum
}

/// Marble: the first material, crossed every 2 units of x by veins of the second (a quarter
/// of each period), bent by turbulence. True for the first material.
pub fn marble(x: f32, y: f32, z: f32) -> bool {
    let phase = x + turbulence(x, y, z);
    phase - 2.0 * (phase * 0.5).floor() < 1.5
}

/// Wood: rings of width 0.5 around the y axis, made irregular by turbulence.
pub fn wood(x: f32, y: f32, z: f32) -> bool {
    let ring = 2.0 * (x * x + z * z).sqrt() + 0.8 * turbulence(x, y, z);
    ring - 2.0 * (ring * 0.5).floor() < 1.0
}

/// Turbulence: blotches where the fractal noise is at least 0 (about half the surface).
pub fn blotches(x: f32, y: f32, z: f32) -> bool {
    fbm(x, y, z) >= 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small deterministic generator of sample points.
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            ((self.0 >> 40) as f32 / (1u64 << 24) as f32) * 20.0 - 10.0
        }
    }

    #[test]
    fn the_permutation_holds_every_byte_once() {
        let mut seen = [false; 256];
        for &p in &PERMUTATION {
            assert!(!seen[p as usize]);
            seen[p as usize] = true;
        }
    }

    #[test]
    fn noise_is_zero_on_the_lattice_bounded_and_continuous() {
        for (x, y, z) in [(0, 0, 0), (3, -2, 7), (-5, 11, -1), (100, 200, -300)] {
            assert_eq!(noise(x as f32, y as f32, z as f32), 0.0, "at {x},{y},{z}");
        }
        let mut rng = Rng(7);
        let step = 1e-3;
        for _ in 0..20_000 {
            let (x, y, z) = (rng.next(), rng.next(), rng.next());
            let n = noise(x, y, z);
            assert!((-1.1..=1.1).contains(&n), "noise {n} at {x},{y},{z}");
            // Lipschitz: the gradient of this noise is bounded (by about 3).
            let moved = noise(x + step, y - step, z + step);
            assert!(
                (moved - n).abs() <= 6.0 * step,
                "jump {n} -> {moved} at {x},{y},{z}"
            );
        }
        // Out of range and NaN inputs give 0, not garbage.
        assert_eq!(noise(1e30, 0.5, 0.5), 0.0);
        assert_eq!(noise(f32::NAN, 0.5, 0.5), 0.0);
    }

    #[test]
    fn noise_averages_zero_and_the_patterns_split_the_surface() {
        let mut rng = Rng(11);
        let n = 40_000;
        let mut sum = 0.0f64;
        let mut counts = [0usize; 3];
        for _ in 0..n {
            let (x, y, z) = (rng.next(), rng.next(), rng.next());
            sum += f64::from(noise(x, y, z));
            counts[0] += usize::from(marble(x, y, z));
            counts[1] += usize::from(wood(x, y, z));
            counts[2] += usize::from(blotches(x, y, z));
        }
        assert!((sum / n as f64).abs() < 0.02, "mean {}", sum / n as f64);
        // Marble is three quarters stone and one quarter veins; the others half and half.
        let expected = [0.75, 0.5, 0.5];
        for ((name, count), want) in ["marble", "wood", "turbulence"]
            .iter()
            .zip(counts)
            .zip(expected)
        {
            let share = count as f64 / n as f64;
            assert!(
                (share - want).abs() < 0.1,
                "{name}: {share}, expected about {want}"
            );
        }
    }

    #[test]
    fn the_same_point_gives_the_same_value_on_every_thread() {
        let points: Vec<(f32, f32, f32)> = {
            let mut rng = Rng(3);
            (0..1000)
                .map(|_| (rng.next(), rng.next(), rng.next()))
                .collect()
        };
        let here: Vec<u32> = points
            .iter()
            .map(|&(x, y, z)| noise(x, y, z).to_bits())
            .collect();
        let there = std::thread::spawn(move || {
            points
                .iter()
                .map(|&(x, y, z)| noise(x, y, z).to_bits())
                .collect::<Vec<u32>>()
        })
        .join()
        .unwrap_or_default();
        assert_eq!(here, there);
    }
}
