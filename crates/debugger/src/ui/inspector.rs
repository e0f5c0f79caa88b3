//! The inspector pane: every field of the selected ray (docs/ray-tree.md), colours with
//! swatches beside their numbers, so the pixel's colour can be read off term by term. A
//! header names the columns; ↑↓ scroll the lines under it and ←→ scroll everything
//! sideways together, so the columns stay aligned with their header. In a pane too narrow
//! for the field names beside the values (unfocused at 80 columns) each line shows its value
//! first and its field name after, wrapped rather than cut, and source locations stand on
//! lines of their own.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Paragraph, Widget, Wrap};
use whitted_tracer::ray_tree::{
    HitInfo, InterfaceInfo, LocalIllumination, RayNode, ShadowInfo, ShadowOutcome, Visibility,
};
use whitted_tracer::{RayKind, Termination};

use crate::action::Focus;
use crate::app::App;
use crate::hit_point::hit_point_view;
use crate::image::ColorDepth;
use crate::tree::state::{NodeId, TreeView};

use super::format::{self, number, swatch, vector};
use super::pane_block;

const LABEL_WIDTH: usize = 13;

/// Below this inner width the values come first: the field names and a vector beside them
/// (`direction     (-0.137, -0.143, 0.980)`) need 38 columns.
const VALUE_FIRST_BELOW: u16 = 40;

pub fn draw(app: &App, pane: Rect, buf: &mut Buffer) {
    let focused = app.focus == Focus::Inspector;
    let Some(picked) = &app.picked else {
        let block = pane_block(Line::from(" Inspector "), focused);
        Paragraph::new(vec![
            Line::from("The selected ray's numbers show here."),
            Line::from(""),
            Line::from("Press ? for every key."),
        ])
        .style(Style::new().fg(Color::Gray))
        .wrap(Wrap { trim: true })
        .block(block)
        .render(pane, buf);
        return;
    };
    let tree = &picked.tree;
    let id = tree.selected();
    let Some(node) = tree.node(id) else {
        return;
    };
    let title = format!(
        " Inspector · {} ray, depth {} ",
        node.kind.name(),
        node.depth
    );
    let mut block = pane_block(Line::from(title), focused);
    let inner = block.inner(pane);
    if inner.width < VALUE_FIRST_BELOW {
        let lines = Lines::value_first(app.color_depth)
            .node(app, tree, id, node)
            .into_iter()
            .flat_map(|line| wrap_pieces(line, usize::from(inner.width)))
            .collect();
        draw_value_first(block, lines, app.inspector_scroll, pane, buf);
        return;
    }
    let lines = Lines::new(app.color_depth).node(app, tree, id, node);
    if inner.height < 2 {
        block.render(pane, buf);
        return;
    }
    let body = Rect {
        y: inner.y + 1,
        height: inner.height - 1,
        ..inner
    };
    let widest = lines.iter().map(Line::width).max().unwrap_or(0);
    let hidden_columns = widest.saturating_sub(usize::from(inner.width));
    let columns = usize::from(app.inspector_columns).min(hidden_columns);
    let hidden_lines = lines.len().saturating_sub(usize::from(body.height));
    let scroll = usize::from(app.inspector_scroll).min(hidden_lines);
    // Say where more is, and which keys bring it.
    let mut more = Vec::new();
    if scroll > 0 || hidden_lines > scroll {
        more.push("↑↓");
    }
    if columns > 0 || hidden_columns > columns {
        more.push("←→");
    }
    if !more.is_empty() {
        block =
            block.title_bottom(Line::from(format!(" more: {} ", more.join(" "))).right_aligned());
    }
    block.render(pane, buf);
    let mut all = vec![header()];
    all.extend(
        lines
            .into_iter()
            .skip(scroll)
            .take(usize::from(body.height)),
    );
    if columns == 0 {
        Paragraph::new(all).render(inner, buf);
        return;
    }
    // Scrolled sideways, the field names stay put and the rest moves under its header.
    let label_width = (LABEL_WIDTH as u16 + 1).min(inner.width);
    let (labels, rest): (Vec<Line<'_>>, Vec<Line<'_>>) = all.into_iter().map(split_label).unzip();
    Paragraph::new(labels).render(
        Rect {
            width: label_width,
            ..inner
        },
        buf,
    );
    Paragraph::new(rest)
        .scroll((0, u16::try_from(columns).unwrap_or(u16::MAX)))
        .render(
            Rect {
                x: inner.x + label_width,
                width: inner.width - label_width,
                ..inner
            },
            buf,
        );
}

/// The narrow inspector: the lines (already wrapped to the pane) under no header, scrolled
/// by ↑↓ only (nothing is wider than the pane).
fn draw_value_first(
    mut block: ratatui::widgets::Block<'static>,
    lines: Vec<Line<'static>>,
    scroll: u16,
    pane: Rect,
    buf: &mut Buffer,
) {
    let inner = block.inner(pane);
    let hidden = lines.len().saturating_sub(usize::from(inner.height));
    let scroll = usize::from(scroll).min(hidden);
    if hidden > 0 {
        block = block.title_bottom(Line::from(" more: ↑↓ ").right_aligned());
    }
    block.render(pane, buf);
    let shown: Vec<Line<'static>> = lines
        .into_iter()
        .skip(scroll)
        .take(usize::from(inner.height))
        .collect();
    Paragraph::new(shown).render(inner, buf);
}

/// `line` in lines of at most `width` cells, broken between its pieces (its spans: value,
/// field name, note; a swatch stays with the numbers after it) two spaces apart, and a piece
/// longer than a line between its words, so that nothing is cut. The lines after the first
/// are indented, so that a field name on the next line reads as its value's.
fn wrap_pieces(line: Line<'static>, width: usize) -> Vec<Line<'static>> {
    const INDENT: &str = "  ";
    let width = width.max(INDENT.len() + 1);
    let mut pieces: Vec<Vec<Span<'static>>> = Vec::new();
    let mut glued = false;
    for span in line.spans {
        let swatch = span.content == "██";
        match pieces.last_mut() {
            Some(piece) if glued => piece.push(span),
            _ => pieces.push(vec![span]),
        }
        glued = swatch;
    }
    let mut lines: Vec<Line<'static>> = Vec::new();
    let mut current: Vec<Span<'static>> = Vec::new();
    let mut used = 0;
    for piece in pieces {
        let piece_width: usize = piece.iter().map(Span::width).sum();
        if !current.is_empty() && used + 2 + piece_width <= width {
            current.push(Span::raw("  "));
            current.extend(piece);
            used += 2 + piece_width;
            continue;
        }
        if !current.is_empty() {
            lines.push(Line::from(std::mem::take(&mut current)));
        }
        let indent = if lines.is_empty() { "" } else { INDENT };
        if indent.len() + piece_width <= width {
            current = vec![Span::raw(indent)];
            current.extend(piece);
            used = indent.len() + piece_width;
            continue;
        }
        // Longer than a line: a text value or a long path, in one style.
        let style = piece.first().map_or(Style::new(), |span| span.style);
        let text: String = piece.iter().map(|span| span.content.as_ref()).collect();
        let first = format::wrap_words(&text, width - indent.len());
        let rest: String = first[1..].join(" ");
        lines.push(Line::from(vec![
            Span::raw(indent),
            Span::styled(first[0].clone(), style),
        ]));
        for row in format::wrap_words(&rest, width - INDENT.len()) {
            if !row.is_empty() {
                lines.push(Line::from(vec![
                    Span::raw(INDENT),
                    Span::styled(row, style),
                ]));
            }
        }
        if let Some(last) = lines.pop() {
            used = last.width();
            current = last.spans;
        }
    }
    if !current.is_empty() || lines.is_empty() {
        lines.push(Line::from(current));
    }
    lines
}

/// A line's field name (its first span, when it fills the label column) and the rest.
/// Section titles have no field name: all of them is the rest.
fn split_label(line: Line<'static>) -> (Line<'static>, Line<'static>) {
    let mut spans = line.spans;
    let is_label = spans
        .first()
        .is_some_and(|span| span.width() == LABEL_WIDTH + 1);
    if is_label {
        let label = spans.remove(0);
        (Line::from(label), Line::from(spans))
    } else {
        (Line::default(), Line::from(spans))
    }
}

/// The column header: the field's name, its value (for a colour, its swatch and then r, g
/// and b over their numbers), and a note on what it is.
fn header() -> Line<'static> {
    let style = Style::new()
        .fg(Color::Gray)
        .add_modifier(Modifier::BOLD | Modifier::UNDERLINED);
    let field = format!("{:<width$}", "field", width = LABEL_WIDTH + 1);
    let rest = format!("{:<7}{:<6}{:<6}{:<3}{}", "value", "r", "g", "b", "note");
    Line::from(vec![Span::styled(field, style), Span::styled(rest, style)])
}

/// Builds the inspector's lines: a label column, then values; or, value first, the value
/// then its field name (a piece each, for [`wrap_pieces`]).
struct Lines {
    depth: ColorDepth,
    value_first: bool,
    out: Vec<Line<'static>>,
}

fn label_style() -> Style {
    Style::new().fg(Color::Gray)
}

fn section_style() -> Style {
    Style::new().add_modifier(Modifier::BOLD)
}

impl Lines {
    fn new(depth: ColorDepth) -> Lines {
        Lines {
            depth,
            value_first: false,
            out: Vec::new(),
        }
    }

    fn value_first(depth: ColorDepth) -> Lines {
        Lines {
            value_first: true,
            ..Lines::new(depth)
        }
    }

    fn text(&mut self, label: &str, value: impl Into<String>) {
        if self.value_first {
            let mut spans = vec![Span::raw(value.into())];
            if !label.trim().is_empty() {
                spans.push(Span::styled(label.trim().to_string(), label_style()));
            }
            self.out.push(Line::from(spans));
            return;
        }
        self.out.push(Line::from(vec![
            Span::styled(format!("{label:<LABEL_WIDTH$} "), label_style()),
            Span::raw(value.into()),
        ]));
    }

    /// Where something is defined: `defined at file:line:col` under its field, or, value
    /// first, the location alone on its line (wrapped, never cut), so that it can be read
    /// in a narrow pane.
    fn location(&mut self, location: &str) {
        if self.value_first {
            self.out.push(Line::from(location.to_string()));
        } else {
            self.text("", format!("defined at {location}"));
        }
    }

    fn color(&mut self, label: &str, c: [f32; 3], note: &str) {
        if self.value_first {
            let mut spans = vec![
                swatch(c, self.depth),
                Span::raw(format!(" {}", format::rgb(c))),
                Span::styled(label.trim().to_string(), label_style()),
            ];
            if !note.is_empty() {
                spans.push(Span::styled(note.to_string(), label_style()));
            }
            self.out.push(Line::from(spans));
            return;
        }
        let mut spans = vec![
            Span::styled(format!("{label:<LABEL_WIDTH$} "), label_style()),
            swatch(c, self.depth),
            Span::raw(format!(" {}", format::rgb(c))),
        ];
        if !note.is_empty() {
            spans.push(Span::styled(format!("  {note}"), label_style()));
        }
        self.out.push(Line::from(spans));
    }

    fn section(&mut self, title: &str) {
        self.out
            .push(Line::from(Span::styled(title.to_string(), section_style())));
    }

    fn node(
        mut self,
        app: &App,
        tree: &TreeView,
        id: NodeId,
        node: &RayNode,
    ) -> Vec<Line<'static>> {
        let whole = tree.tree();
        let [x, y] = whole.pixel;
        self.color(
            &format!("pixel {x},{y}"),
            whole.color,
            "its rendered colour",
        );
        if let Some(sample) = tree.sample(id) {
            if whole.samples_per_pixel > 1 {
                self.color(
                    &format!("sample {}", sample.index),
                    sample.color,
                    &format!("of {}", whole.samples_per_pixel),
                );
            }
        }
        self.text("origin", vector(node.origin));
        self.text("direction", vector(node.direction));
        self.color("path weight", node.weight, "share of the pixel");
        if matches!(node.kind, RayKind::Reflected | RayKind::Transmitted) {
            let name = if node.kind == RayKind::Reflected {
                "kr"
            } else {
                "kt"
            };
            self.color("coefficient", node.coefficient, name);
        }
        if let Some(interface) = &node.interface {
            self.interface(interface);
        }
        if let Some(shadow) = &node.shadow {
            self.shadow(shadow);
            if let Some(light) = tree.light_of_shadow(id) {
                self.color(
                    "light share",
                    format::add(light.diffuse, light.specular),
                    "diffuse + specular at the hit",
                );
            }
            self.color("returned", node.color, "light let through");
        } else {
            match &node.hit {
                Some(hit) => self.hit(hit),
                None => self.text("hit", "nothing: the ray left the scene"),
            }
            if node.hit.is_some() {
                if let Some(view) = hit_point_view(app) {
                    self.text("on screen", view.describe());
                }
            }
            if let Some(local) = &node.local {
                self.local(local, whole.model.highlight);
            }
            self.why_this_colour(node);
        }
        self.color("contributes", tree.contribution(id), "weight × returned");
        self.text("ended", termination(node));
        for skipped in &node.skipped {
            self.text(
                "not traced",
                format!(
                    "{} ray (depth {}): {}",
                    skipped.kind.name(),
                    skipped.depth,
                    reason(skipped.reason)
                ),
            );
            self.color("  weight", skipped.weight, "it would have had");
        }
        self.out
    }

    fn interface(&mut self, interface: &InterfaceInfo) {
        let side = if interface.entering {
            "entering the solid"
        } else {
            "leaving the solid"
        };
        self.text(
            "leaves from",
            format!("incidence {:.1}°, {side}", interface.incidence_degrees),
        );
        if let Some([from, to]) = interface.ior {
            self.text("ior", format!("{} → {}", number(from), number(to)));
        }
        if let (Some(r), Some(t)) = (
            interface.fresnel_reflectance,
            interface.fresnel_transmittance,
        ) {
            self.text("Fresnel", format!("R {}  T {}", number(r), number(t)));
        }
        if interface.total_internal_reflection {
            self.text("", "total internal reflection");
        }
    }

    fn hit(&mut self, hit: &HitInfo) {
        self.text(
            "hit at t",
            format!("{}  point {}", number(hit.t), vector(hit.point)),
        );
        self.text(
            "object",
            format!("{} ({})", hit.object.label, hit.object.kind),
        );
        self.location(&hit.object.location);
        if hit.leaf.handle != hit.object.handle {
            self.text("leaf", format!("{} ({})", hit.leaf.label, hit.leaf.kind));
            self.location(&hit.leaf.location);
        }
        if !hit.csg_path.is_empty() {
            let path: Vec<String> = hit
                .csg_path
                .iter()
                .map(|o| format!("{} {}", o.kind, o.label))
                .collect();
            self.text("csg", path.join(" › "));
        }
        let face = if hit.front_face {
            "front face"
        } else {
            "back face (inside)"
        };
        self.text(
            "normal",
            format!("{}  {face}", vector(hit.geometric_normal)),
        );
        if hit.shading_normal != hit.geometric_normal {
            self.text(
                "shading",
                format!("{}  faces the ray", vector(hit.shading_normal)),
            );
        }
        self.text("material", hit.material.label.clone());
        self.location(&hit.material.location);
        if hit.resolved_material.handle != hit.material.handle {
            self.text("pattern →", hit.resolved_material.label.clone());
        }
        if hit.absorption != [1.0; 3] {
            self.color("absorption", hit.absorption, "Beer-Lambert on the way here");
        }
        self.text(
            "offset",
            format!("{:.1e}  (error bound {:.1e})", hit.offset, hit.error_bound),
        );
        for other in &hit.coincident {
            self.text(
                "coincident",
                format!(
                    "{} ({}) in the same place: z-fighting",
                    other.object.label, other.object.kind
                ),
            );
            self.location(&other.object.location);
        }
    }

    fn local(&mut self, local: &LocalIllumination, highlight: whitted_ir::Highlight) {
        self.section("local illumination");
        self.color("ambient", local.ambient, "ka·Ia·kd");
        // Most surfaces give off no light: show the line only for those that do.
        if local.emission != [0.0; 3] {
            self.color("emission", local.emission, "the surface's own light");
        }
        for light in &local.lights {
            let mut facts = vec![
                match light.visibility {
                    Visibility::Lit => "lit".to_string(),
                    Visibility::Filtered => "filtered".to_string(),
                    Visibility::Blocked => "in shadow".to_string(),
                    Visibility::FacingAway => "faces away: N·L <= 0 (no shadow ray)".to_string(),
                    Visibility::OutsideCone => match &light.cone {
                        Some(cone) => format!(
                            "outside the spot cone: {:.1}° from its axis, cone {:.1}° (no shadow ray)",
                            cone.angle_degrees, cone.outer_degrees
                        ),
                        None => "outside the spot cone (no shadow ray)".to_string(),
                    },
                    Visibility::BlackLight => {
                        "black light: adds nothing (no shadow ray)".to_string()
                    }
                    Visibility::TooFaint => {
                        "too faint: fatt·spot rounds to 0 (no shadow ray)".to_string()
                    }
                    Visibility::Unshaded => "nothing to light (no shadow ray)".to_string(),
                    Visibility::NoShadows => "lit (shadows none: no shadow ray)".to_string(),
                    Visibility::BackFace => "unlit back face (shade_back off)".to_string(),
                },
                format!("N·L {}", number(light.n_dot_l)),
            ];
            if light.attenuation != 1.0 {
                facts.push(format!("fatt {}", number(light.attenuation)));
            }
            if light.spot != 1.0 {
                facts.push(format!("spot {}", number(light.spot)));
            }
            self.text(&format!("light {}", light.light.label), facts.join(" · "));
            self.color("  diffuse", light.diffuse, "kd·(N·L)");
            let specular = match highlight {
                whitted_ir::Highlight::Phong => "ks·(R·V)^n",
                whitted_ir::Highlight::Blinn => "ks·(N·H)^n",
            };
            self.color("  specular", light.specular, specular);
        }
        self.color("local total", local.total, "");
    }

    /// The returned colour as the tracer adds it up: the local colour, plus each traced
    /// secondary ray's colour times its coefficient, all times the absorption on the way.
    fn why_this_colour(&mut self, node: &RayNode) {
        self.section("returned colour");
        let Some(local) = &node.local else {
            self.color("background", node.color, "the scene's background");
            return;
        };
        self.color("local", local.total, "ambient + lights");
        for child in &node.children {
            let (label, coefficient) = match child.kind {
                RayKind::Reflected => ("+ reflected", "kr"),
                RayKind::Transmitted => ("+ transmitted", "kt"),
                RayKind::Camera | RayKind::Shadow => continue,
            };
            self.color(
                label,
                format::mul(child.coefficient, child.color),
                &format!("{coefficient} × its colour"),
            );
        }
        if let Some(hit) = &node.hit {
            if hit.absorption != [1.0; 3] {
                self.color("× absorption", hit.absorption, "");
            }
        }
        self.color("= returned", node.color, "");
    }

    fn shadow(&mut self, shadow: &ShadowInfo) {
        let light = format!("{} ({})", shadow.light.label, shadow.light.kind);
        if self.value_first {
            self.text("towards", light);
            self.location(&shadow.light.location);
        } else {
            self.text("towards", format!("{light}  {}", shadow.light.location));
        }
        self.text(
            "max t",
            match shadow.max_t {
                Some(t) => number(t),
                None => "none (directional light)".to_string(),
            },
        );
        let mut blocker_location = None;
        let result = match shadow.result {
            ShadowOutcome::Unblocked => "reached the light".to_string(),
            ShadowOutcome::Blocked => match &shadow.blocker {
                Some(blocker) => {
                    let blocked = format!(
                        "blocked by {} at t {}",
                        blocker.object.label,
                        number(blocker.t)
                    );
                    if self.value_first {
                        blocker_location = Some(blocker.object.location.as_str());
                        blocked
                    } else {
                        format!("{blocked}  {}", blocker.object.location)
                    }
                }
                None => "blocked".to_string(),
            },
            ShadowOutcome::Filtered => {
                format!("filtered through {} object(s)", shadow.filters.unwrap_or(0))
            }
        };
        self.text("result", result);
        if let Some(location) = blocker_location {
            self.location(location);
        }
        if let Some(transmittance) = shadow.transmittance {
            self.color("transmittance", transmittance, "");
        }
    }
}

fn termination(node: &RayNode) -> String {
    let shadow = node.kind == RayKind::Shadow;
    match node.termination {
        Termination::NotEnded => "not ended: it spawned secondary rays".to_string(),
        Termination::Miss if shadow => "reached the light".to_string(),
        Termination::Miss => "miss: the background colour returns".to_string(),
        Termination::Absorbed if shadow => "stopped by a blocker".to_string(),
        other => reason(other).to_string(),
    }
}

fn reason(termination: Termination) -> &'static str {
    match termination {
        Termination::NotEnded => "not ended",
        Termination::Miss => "miss",
        Termination::MaxDepth => "max depth: a deeper ray would pass the depth limit",
        Termination::WeightCutoff => "weight cut-off: it would weigh less than min_weight",
        Termination::TotalInternalReflection => "total internal reflection",
        Termination::Absorbed => "absorbed: the surface neither reflects nor transmits",
        Termination::RayBudget => {
            "ray budget: the sample had cast its budget of rays (rays per sample, docs/language.md)"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn local_text(emission: [f32; 3]) -> String {
        let local = LocalIllumination {
            ambient: [0.1; 3],
            emission,
            lights: Vec::new(),
            total: [0.1 + emission[0], 0.1 + emission[1], 0.1 + emission[2]],
        };
        text_of(&local, whitted_ir::Highlight::Phong)
    }

    fn text_of(local: &LocalIllumination, highlight: whitted_ir::Highlight) -> String {
        let mut lines = Lines::new(ColorDepth::TrueColor);
        lines.local(local, highlight);
        lines
            .out
            .iter()
            .map(|line| {
                line.spans
                    .iter()
                    .map(|span| span.content.as_ref())
                    .collect::<String>()
            })
            .collect::<Vec<_>>()
            .join("\n")
    }

    /// A self-lit surface shows its emission among the local terms; other surfaces show no
    /// such line (so every existing screen stays as it was).
    #[test]
    fn the_emission_line_shows_only_for_surfaces_that_give_off_light() {
        let glowing = local_text([0.5, 0.25, 0.0]);
        assert!(glowing.contains("emission"), "{glowing}");
        assert!(glowing.contains("0.500 0.250 0.000"), "{glowing}");
        let plain = local_text([0.0; 3]);
        assert!(!plain.contains("emission"), "{plain}");
        assert!(plain.contains("ambient"), "{plain}");
    }

    /// A light that adds nothing says why, in the tracer's words: a spot cone that misses
    /// the point with its angles, a light behind the surface, a black light.
    #[test]
    fn a_light_that_adds_nothing_says_why() {
        let light = |visibility, n_dot_l, cone| whitted_tracer::ray_tree::LightContribution {
            light: whitted_tracer::ray_tree::LightRef {
                handle: 0,
                name: Some("torch".into()),
                label: "torch".into(),
                kind: "spot".into(),
                location: "s.scene:3:1".into(),
                span: whitted_ir::Span::detached(),
            },
            to_light: [0.0, 1.0, 0.0],
            distance: Some(5.0),
            n_dot_l,
            attenuation: 1.0,
            spot: 0.0,
            cone,
            diffuse: [0.0; 3],
            specular: [0.0; 3],
            visibility,
            shadow_child: None,
        };
        let cone = whitted_tracer::ray_tree::ConeInfo {
            angle_degrees: 52.3,
            inner_degrees: 20.0,
            outer_degrees: 30.0,
        };
        let local = LocalIllumination {
            ambient: [0.0; 3],
            emission: [0.0; 3],
            lights: vec![
                light(Visibility::OutsideCone, 0.607, Some(cone)),
                light(Visibility::FacingAway, -0.25, Some(cone)),
                light(Visibility::BlackLight, 0.5, None),
            ],
            total: [0.0; 3],
        };
        let text = text_of(&local, whitted_ir::Highlight::Phong);
        let lines: Vec<&str> = text.lines().filter(|l| l.contains("torch")).collect();
        assert_eq!(lines.len(), 3, "{text}");
        assert!(
            lines[0].contains("outside the spot cone: 52.3° from its axis, cone 30.0°")
                && !lines[0].contains("faces away"),
            "{text}"
        );
        assert!(lines[1].contains("faces away: N·L <= 0"), "{text}");
        assert!(lines[2].contains("black light"), "{text}");
    }

    fn plain(lines: &[Line<'static>]) -> Vec<String> {
        lines
            .iter()
            .map(|line| line.spans.iter().map(|s| s.content.as_ref()).collect())
            .collect()
    }

    /// Value first, a line breaks between its value, field name and note, a value longer
    /// than the pane between its words, and a path longer than the pane inside it: nothing
    /// is cut, and a swatch stays with its numbers.
    #[test]
    fn narrow_lines_wrap_between_pieces_and_never_cut() {
        let mut lines = Lines::value_first(ColorDepth::TrueColor);
        lines.color(
            "pixel 400,270",
            [0.189, 0.292, 0.693],
            "its rendered colour",
        );
        lines.text("hit at t", "4.406  point (-0.606, 0.971, -2.181)");
        lines.location("scenes/a-rather-long-folder-name/whitted.scene:20:1");
        let wrapped: Vec<Line<'static>> = lines
            .out
            .into_iter()
            .flat_map(|line| wrap_pieces(line, 30))
            .collect();
        assert_eq!(
            plain(&wrapped),
            [
                "██ 0.189 0.292 0.693",
                "  pixel 400,270",
                "  its rendered colour",
                "4.406 point (-0.606, 0.971,",
                "  -2.181)  hit at t",
                "scenes/a-rather-long-folder-na",
                "  me/whitted.scene:20:1",
            ]
        );
        assert!(wrapped.iter().all(|line| line.width() <= 30));
    }

    #[test]
    fn the_specular_line_names_the_scene_s_highlight_model() {
        let light = whitted_tracer::ray_tree::LightContribution {
            light: whitted_tracer::ray_tree::LightRef {
                handle: 0,
                name: None,
                label: "light #0".into(),
                kind: "directional".into(),
                location: "<built-in>".into(),
                span: whitted_ir::Span::detached(),
            },
            to_light: [0.0, 1.0, 0.0],
            distance: None,
            n_dot_l: 1.0,
            attenuation: 1.0,
            spot: 1.0,
            cone: None,
            diffuse: [0.5; 3],
            specular: [0.25; 3],
            visibility: Visibility::NoShadows,
            shadow_child: None,
        };
        let local = LocalIllumination {
            ambient: [0.0; 3],
            emission: [0.0; 3],
            lights: vec![light],
            total: [0.75; 3],
        };
        let blinn = text_of(&local, whitted_ir::Highlight::Blinn);
        assert!(blinn.contains("ks·(N·H)^n"), "{blinn}");
        assert!(
            blinn.contains("lit (shadows none: no shadow ray)"),
            "{blinn}"
        );
        let phong = text_of(&local, whitted_ir::Highlight::Phong);
        assert!(
            phong.contains("ks·(R·V)^n") && !phong.contains("N·H"),
            "{phong}"
        );
    }
}
