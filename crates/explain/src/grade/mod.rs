//! `whitted grade`: which classic bug explains a student's image. The reference is rendered,
//! then the scene again under each student bug model ([`models::BUGS`]) alone and under
//! pairs of the best, and every render is scored by how many of the differing pixels it
//! makes match the student's (and how many matching ones it breaks). Renders go through
//! `whitted_tracer::render` (all cores) and are cached by their settings, so a class graded
//! on one command line renders each model once. The library renders and scores; the binary
//! reads images, writes pictures and prints.

pub mod models;
mod picture;
mod score;

use std::collections::HashMap;
use std::sync::Arc;

use whitted_ir::{setting_rows, ValidScene};
use whitted_tracer::display::linear_to_srgb8;
use whitted_tracer::{NoObserver, PreparedScene, RenderOptions};

pub use models::{Change, StudentBug, BUGS};
pub use picture::side_by_side;
pub use score::Score;

/// How many of the best single models are paired with every other model: a second bug
/// often matches nothing alone (the first one changes every pixel it touches too).
const PAIRED: usize = 3;

/// How 8-bit values encode light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Colour times 255, clamped and rounded: the MIT 6.837 course's images.
    Linear,
    /// The sRGB curve: `whitted render`'s PNG, TGA and PPM.
    Srgb,
}

impl Encoding {
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Linear => "linear",
            Encoding::Srgb => "srgb",
        }
    }

    pub fn other(self) -> Encoding {
        match self {
            Encoding::Linear => Encoding::Srgb,
            Encoding::Srgb => Encoding::Linear,
        }
    }

    /// `pixels` (linear light) in this encoding's 8 bits, three bytes a pixel.
    pub fn encode(self, pixels: &[[f32; 3]]) -> Vec<u8> {
        let one = |c: f32| match self {
            Encoding::Linear => (c.clamp(0.0, 1.0) * 255.0).round() as u8,
            Encoding::Srgb => linear_to_srgb8(c),
        };
        pixels.iter().flatten().map(|&c| one(c)).collect()
    }

    /// One pixel in this encoding's 8 bits.
    pub fn encode_one(self, pixel: [f32; 3]) -> [u8; 3] {
        let bytes = self.encode(&[pixel]);
        [bytes[0], bytes[1], bytes[2]]
    }
}

/// One explanation tried: one model or a pair, and how well it matches the student.
#[derive(Clone, Debug)]
pub struct Candidate {
    pub bugs: Vec<&'static StudentBug>,
    pub score: Score,
    /// Other models whose render is the same image (indistinguishable in this scene).
    pub same_as: Vec<&'static StudentBug>,
}

impl Candidate {
    /// The ids joined with `+`.
    pub fn id(&self) -> String {
        self.bugs.iter().map(|b| b.id).collect::<Vec<_>>().join("+")
    }
}

/// What grading one image found.
#[derive(Clone, Debug)]
pub struct Grade {
    pub width: u32,
    pub height: u32,
    /// Pixels whose student and reference values differ by more than the tolerance.
    pub differing: u64,
    /// The sum of absolute 8-bit differences between student and reference, all channels.
    pub difference_energy: u64,
    /// Every candidate that explains more differing pixels than it breaks, best first.
    pub ranked: Vec<Candidate>,
    /// Models that change nothing in this scene (they cannot be told from a correct tracer).
    pub invisible: Vec<&'static StudentBug>,
    /// The best candidate's image, in the student's encoding (the reference when nothing
    /// explains anything).
    pub best_image: Vec<u8>,
    pub reference_image: Vec<u8>,
}

/// The verdict a teacher reads first.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// No pixel (beyond the tolerance) differs.
    Matches,
    /// The best candidate explains at least half of the differing pixels.
    Explained,
    /// Nothing explains half of them: a bug outside the models (or several).
    Unexplained,
}

impl Grade {
    pub fn verdict(&self) -> Verdict {
        if self.differing == 0 {
            return Verdict::Matches;
        }
        match self.ranked.first() {
            Some(best) if best.score.share(self.differing) >= 0.5 => Verdict::Explained,
            _ => Verdict::Unexplained,
        }
    }

    /// The best explanation, when there is one.
    pub fn best(&self) -> Option<&Candidate> {
        (self.verdict() == Verdict::Explained)
            .then(|| self.ranked.first())
            .flatten()
    }
}

/// Settings written on top of the reference's: (name, value as `--set` writes it).
type Assignments = Vec<(&'static str, String)>;

/// Grades images against one scene, keeping every render it makes.
pub struct Grader<'a> {
    scene: &'a ValidScene,
    encoding: Encoding,
    renders: HashMap<Assignments, Arc<Vec<[f32; 3]>>>,
    /// Renders made so far (cache hits not counted).
    pub render_count: u32,
}

impl<'a> Grader<'a> {
    /// `scene` holds every setting (the command line's applied); `encoding` is the space the
    /// students' images are written in.
    pub fn new(scene: &'a ValidScene, encoding: Encoding) -> Self {
        Grader {
            scene,
            encoding,
            renders: HashMap::new(),
            render_count: 0,
        }
    }

    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    /// The reference in the students' encoding.
    pub fn reference(&mut self) -> Result<Vec<u8>, String> {
        let pixels = self.render(&[])?;
        Ok(self.encoding.encode(&pixels))
    }

    /// The scene rendered with `assignments` on top of its settings (cached).
    fn render(
        &mut self,
        assignments: &[(&'static str, String)],
    ) -> Result<Arc<Vec<[f32; 3]>>, String> {
        let mut key = assignments.to_vec();
        key.sort();
        if let Some(pixels) = self.renders.get(&key) {
            return Ok(Arc::clone(pixels));
        }
        let mut scene = self.scene.scene().clone();
        for (name, value) in &key {
            let row = setting_rows::setting(name).ok_or_else(|| format!("no setting `{name}`"))?;
            let value = row.parse(value)?;
            (row.set)(&mut scene.settings, value);
        }
        let valid = whitted_ir::validate(scene).map_err(|invalid| {
            invalid
                .diagnostics
                .iter()
                .map(|d| d.message.clone())
                .collect::<Vec<_>>()
                .join("; ")
        })?;
        let options = RenderOptions::from_settings(&valid.scene().settings);
        let prepared = PreparedScene::new(&valid);
        let (image, _) = whitted_tracer::render(&prepared, &options, &NoObserver)
            .ok_or_else(|| "the render was cancelled".to_string())?;
        self.render_count += 1;
        let pixels = Arc::new(image.pixels);
        self.renders.insert(key, Arc::clone(&pixels));
        Ok(pixels)
    }

    /// The image `bugs` make together, in the students' encoding; `None` when one of them
    /// cannot show in this scene or two set the same setting.
    fn image_of(&mut self, bugs: &[&'static StudentBug]) -> Result<Option<Vec<u8>>, String> {
        let settings = &self.scene.scene().settings;
        let mut assignments: Vec<(&'static str, String)> = Vec::new();
        let mut encoding = self.encoding;
        let (mut flipped, mut swapped) = (false, false);
        for bug in bugs {
            match (bug.change)(settings) {
                None => return Ok(None),
                Some(Change::OtherEncoding) => encoding = encoding.other(),
                Some(Change::UpsideDown) => flipped = true,
                Some(Change::RedBlueSwapped) => swapped = true,
                Some(Change::Set(set)) => {
                    for (name, value) in set {
                        if assignments.iter().any(|(n, _)| *n == name) {
                            return Ok(None);
                        }
                        assignments.push((name, value));
                    }
                }
            }
        }
        let pixels = self.render(&assignments)?;
        let mut bytes = encoding.encode(&pixels);
        let row = self.scene.scene().settings.width as usize * 3;
        if flipped && row > 0 {
            bytes = bytes.chunks_exact(row).rev().flatten().copied().collect();
        }
        if swapped {
            for pixel in bytes.chunks_exact_mut(3) {
                pixel.swap(0, 2);
            }
        }
        Ok(Some(bytes))
    }

    /// Grades the student's 8-bit image (in the grader's encoding, the scene's size).
    /// `tolerance` is the largest difference on any channel that still counts as equal.
    pub fn grade(&mut self, student: &[u8], tolerance: u8) -> Result<Grade, String> {
        let settings = &self.scene.scene().settings;
        let (width, height) = (settings.width, settings.height);
        let reference = self.reference()?;
        if student.len() != reference.len() {
            return Err(format!(
                "the student's image has {} values, the reference {} ({width}x{height})",
                student.len(),
                reference.len()
            ));
        }
        let baseline = score::Baseline::new(student, &reference, tolerance);
        let mut grade = Grade {
            width,
            height,
            differing: baseline.differing,
            difference_energy: baseline.energy,
            ranked: Vec::new(),
            invisible: Vec::new(),
            best_image: reference.clone(),
            reference_image: reference.clone(),
        };
        if baseline.differing == 0 {
            return Ok(grade);
        }
        // Singles: every model that can show in this scene.
        let mut images: Vec<(Vec<&'static StudentBug>, Vec<u8>)> = Vec::new();
        for bug in BUGS {
            match self.image_of(&[bug])? {
                Some(image) if image == reference => grade.invisible.push(bug),
                Some(image) => images.push((vec![bug], image)),
                None => {}
            }
        }
        let mut singles = scored(&baseline, student, images);
        // Pairs: each of the best singles with every other model that shows in this scene.
        // A pair stays when it explains clearly more than either of its models alone.
        let best: Vec<&'static StudentBug> = singles
            .iter()
            .filter(|c| c.0.score.net() > 0)
            .take(PAIRED)
            .map(|c| c.0.bugs[0])
            .collect();
        let visible: Vec<&'static StudentBug> = singles
            .iter()
            .flat_map(|c| std::iter::once(c.0.bugs[0]).chain(c.0.same_as.iter().copied()))
            .collect();
        let mut pair_images = Vec::new();
        let mut tried: Vec<(&str, &str)> = Vec::new();
        for a in &best {
            for b in &visible {
                let (first, second) = if catalogue_index(a) < catalogue_index(b) {
                    (*a, *b)
                } else {
                    (*b, *a)
                };
                if first.id == second.id || tried.contains(&(first.id, second.id)) {
                    continue;
                }
                tried.push((first.id, second.id));
                let pair = vec![first, second];
                if let Some(image) = self.image_of(&pair)? {
                    pair_images.push((pair, image));
                }
            }
        }
        let margin = (baseline.differing / 50).max(2) as i64;
        let single_net = |bug: &StudentBug| {
            singles
                .iter()
                .find(|c| c.0.bugs[0].id == bug.id)
                .map_or(0, |c| c.0.score.net())
        };
        let pairs: Vec<(Candidate, Vec<u8>)> = scored(&baseline, student, pair_images)
            .into_iter()
            .filter(|(pair, _)| {
                let alone = single_net(pair.bugs[0]).max(single_net(pair.bugs[1]));
                pair.score.net() > alone + margin
            })
            .collect();
        singles.extend(pairs);
        singles.retain(|(c, _)| c.score.net() > 0);
        singles.sort_by(|(a, _), (b, _)| {
            b.score
                .net()
                .cmp(&a.score.net())
                .then(a.score.residual_energy.cmp(&b.score.residual_energy))
                .then(a.bugs.len().cmp(&b.bugs.len()))
        });
        if let Some((_, image)) = singles.first() {
            grade.best_image = image.clone();
        }
        grade.ranked = singles.into_iter().map(|(c, _)| c).collect();
        Ok(grade)
    }
}

fn catalogue_index(bug: &StudentBug) -> usize {
    BUGS.iter()
        .position(|b| b.id == bug.id)
        .unwrap_or(usize::MAX)
}

/// Scores each image, folding models whose images are identical into one candidate (the
/// first in catalogue order, the others in `same_as`), best first.
fn scored(
    baseline: &score::Baseline,
    student: &[u8],
    images: Vec<(Vec<&'static StudentBug>, Vec<u8>)>,
) -> Vec<(Candidate, Vec<u8>)> {
    let mut out: Vec<(Candidate, Vec<u8>)> = Vec::new();
    for (bugs, image) in images {
        if let Some((same, _)) = out.iter_mut().find(|(_, other)| *other == image) {
            if bugs.len() == 1 {
                same.same_as.push(bugs[0]);
            }
            continue;
        }
        let score = baseline.score(student, &image);
        out.push((
            Candidate {
                bugs,
                score,
                same_as: Vec::new(),
            },
            image,
        ));
    }
    out.sort_by_key(|(c, _)| std::cmp::Reverse(c.score.net()));
    out
}
