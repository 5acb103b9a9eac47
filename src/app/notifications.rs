//! Short messages in the corner: errors stay until dismissed, information fades after a few seconds.

use std::time::Duration;

use egui::{Align2, Color32, RichText};

const INFO_SECONDS: f64 = 4.0;

struct Notification {
    text: String,
    error: bool,
    /// Set on the first frame it is shown.
    shown_at: Option<f64>,
}

#[derive(Default)]
pub struct Notifications {
    items: Vec<Notification>,
}

impl Notifications {
    pub fn error(&mut self, text: String) {
        self.items.push(Notification { text, error: true, shown_at: None });
    }

    pub fn info(&mut self, text: String) {
        self.items.push(Notification { text, error: false, shown_at: None });
    }

    pub fn ui(&mut self, ctx: &egui::Context) {
        let now = ctx.input(|i| i.time);
        self.items.retain(|n| n.error || n.shown_at.is_none_or(|t| now - t < INFO_SECONDS));
        if self.items.is_empty() {
            return;
        }
        let mut dismissed = None;
        egui::Area::new(egui::Id::unique("notifications")).anchor(Align2::RIGHT_BOTTOM, egui::vec2(-12.0, -60.0)).show(
            ctx,
            |ui| {
                for (i, n) in self.items.iter_mut().enumerate() {
                    n.shown_at.get_or_insert(now);
                    egui::Frame::popup(ui.style()).show(ui, |ui| {
                        ui.set_max_width(520.0);
                        ui.horizontal(|ui| {
                            let (label, color) = if n.error {
                                ("Error", Color32::from_rgb(235, 64, 100))
                            } else {
                                ("Info", ui.visuals().text_color())
                            };
                            ui.label(RichText::new(label).strong().color(color));
                            ui.label(&n.text);
                            if ui.small_button("Dismiss").clicked() {
                                dismissed = Some(i);
                            }
                        });
                    });
                }
            },
        );
        if let Some(i) = dismissed {
            self.items.remove(i);
        }
        if self.items.iter().any(|n| !n.error) {
            ctx.request_repaint_after(Duration::from_millis(500));
        }
    }
}
