//! Short messages in the corner: errors stay until dismissed (or until what they were about is fixed), information
//! fades after a few seconds.
//!
//! They are built not to get in the way: they stack in the viewport's lower left corner (never over a control, and
//! clear of the caption the viewport draws at its lower right), each as wide as the stack, its file's name first and its text wrapped (never cut); nothing fades or moves while
//! the pointer is over them (so a click meant for Dismiss never lands on the viewport behind), a message repeated
//! collapses into one with a count, and at most a few are shown, the rest counted.

use std::time::Duration;

use egui::{Align2, Color32, Rect, RichText};

const INFO_SECONDS: f64 = 4.0;

/// The most messages shown at once; older ones are summarised.
const MAX_SHOWN: usize = 4;

struct Notification {
    text: String,
    error: bool,
    /// What the message is about (a file's path), so that fixing it can clear it.
    topic: Option<String>,
    /// How many times it was said.
    count: usize,
    /// When it was last said or last hovered, on the first frame after.
    shown_at: Option<f64>,
}

#[derive(Default)]
pub struct Notifications {
    items: Vec<Notification>,
    /// Where they were drawn last frame: while the pointer is there they hold still.
    area: Option<egui::Rect>,
}

impl Notifications {
    /// An error about `topic` (a file), kept until dismissed or [`Notifications::resolved`].
    pub fn error_about(&mut self, topic: &str, text: String) {
        self.push(text, true, Some(topic.to_owned()));
    }

    pub fn info(&mut self, text: String) {
        self.push(text, false, None);
    }

    /// Information about `topic` (a file): shown under the file's name.
    pub fn info_about(&mut self, topic: &str, text: String) {
        self.push(text, false, Some(topic.to_owned()));
    }

    /// Drops the errors about `topic`: it loaded after all.
    pub fn resolved(&mut self, topic: &str) {
        self.items.retain(|n| !(n.error && n.topic.as_deref() == Some(topic)));
    }

    /// Drops every error: another document opened.
    pub fn clear_errors(&mut self) {
        self.items.retain(|n| !n.error);
    }

    /// Where they were drawn last frame.
    pub fn rect(&self) -> Option<egui::Rect> {
        self.area
    }

    /// The errors kept, each with how many times it was said.
    pub fn errors(&self) -> Vec<(String, usize)> {
        self.items.iter().filter(|n| n.error).map(|n| (n.text.clone(), n.count)).collect()
    }

    fn push(&mut self, text: String, error: bool, topic: Option<String>) {
        // A path or a name in a message may hold control characters: shown escaped, on one line.
        let text = crate::import::text::printable(&text).into_owned();
        // Said again, a message counts once more and comes to the front, where the latest are shown.
        let same = self.items.iter().position(|n| n.text == text && n.error == error && n.topic == topic);
        let count = same.map_or(1, |i| self.items.remove(i).count + 1);
        self.items.push(Notification { text, error, topic, count, shown_at: None });
    }

    /// Shows the messages in the lower left corner of `within` (a part of the viewport), as wide as it.
    pub fn ui(&mut self, ctx: &egui::Context, within: Rect) {
        let now = ctx.input(|i| i.time);
        let hovered =
            self.area.is_some_and(|area| ctx.input(|i| i.pointer.hover_pos()).is_some_and(|p| area.contains(p)));
        if hovered {
            self.items.iter_mut().for_each(|n| n.shown_at = Some(now));
        } else {
            self.items.retain(|n| n.error || n.shown_at.is_none_or(|t| now - t < INFO_SECONDS));
        }
        if self.items.is_empty() {
            self.area = None;
            return;
        }
        let width = (within.width() - 2.0 * MARGIN).clamp(MIN_WIDTH, MAX_WIDTH);
        let mut dismissed = None;
        let hidden = self.items.len().saturating_sub(MAX_SHOWN);
        let response = egui::Area::new(egui::Id::unique("notifications"))
            .pivot(Align2::LEFT_BOTTOM)
            .fixed_pos(within.left_bottom() + egui::vec2(MARGIN, -MARGIN))
            .show(ctx, |ui| {
                ui.set_width(width);
                if hidden > 0 {
                    ui.label(RichText::new(format!("{hidden} older messages")).weak());
                }
                for (i, n) in self.items.iter_mut().enumerate().skip(hidden) {
                    n.shown_at.get_or_insert(now);
                    if n.ui(ui, width) {
                        dismissed = Some(i);
                    }
                }
            });
        self.area = Some(response.response.rect);
        if let Some(i) = dismissed {
            self.items.remove(i);
        }
        if self.items.iter().any(|n| !n.error) {
            ctx.request_repaint_after(Duration::from_millis(500));
        }
    }
}

/// Points between the messages and the viewport's edges.
const MARGIN: f32 = 10.0;
/// The share of the viewport's width, at its right, left to the caption (file, clip, time, modes).
pub const CAPTION_SIDE: f32 = 0.4;
/// The width of the stack: as wide as its place allows, up to a readable line.
const MIN_WIDTH: f32 = 130.0;
const MAX_WIDTH: f32 = 480.0;

impl Notification {
    /// One message `width` wide: its kind, its file's name and Dismiss on a line, the text wrapped below. Returns
    /// whether it was dismissed.
    fn ui(&self, ui: &mut egui::Ui, width: f32) -> bool {
        let mut dismissed = false;
        egui::Frame::popup(ui.style()).show(ui, |ui| {
            ui.set_width(width - 2.0 * ui.style().spacing.window_margin.leftf());
            ui.horizontal(|ui| {
                let (kind, color) = if self.error {
                    ("Error", Color32::from_rgb(235, 64, 100))
                } else {
                    ("Info", ui.visuals().text_color())
                };
                ui.label(RichText::new(kind).strong().color(color));
                ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                    dismissed = ui.small_button("Dismiss").clicked();
                    if let Some(topic) = &self.topic {
                        let name = std::path::Path::new(topic)
                            .file_name()
                            .map_or(topic.as_str(), |n| n.to_str().unwrap_or(topic));
                        let name = crate::import::text::printable(name).into_owned();
                        ui.with_layout(egui::Layout::left_to_right(egui::Align::Center), |ui| {
                            super::text::name_label(ui, &name, || name.clone(), ui.available_width(), None)
                                .on_hover_text(topic);
                        });
                    }
                });
            });
            let times = if self.count > 1 { format!(" (×{})", self.count) } else { String::new() };
            ui.add(egui::Label::new(format!("{}{times}", self.text)).wrap());
        });
        dismissed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeats_collapse_and_fixed_files_clear_their_errors() {
        let mut notifications = Notifications::default();
        for _ in 0..70 {
            notifications.error_about("a.glb", "not reloaded: a.glb: truncated".to_owned());
        }
        notifications.error_about("b.glb", "b.glb: bad".to_owned());
        assert_eq!(
            notifications.errors(),
            [("not reloaded: a.glb: truncated".to_owned(), 70), ("b.glb: bad".to_owned(), 1)]
        );
        notifications.resolved("a.glb");
        assert_eq!(notifications.errors(), [("b.glb: bad".to_owned(), 1)]);
    }
}
