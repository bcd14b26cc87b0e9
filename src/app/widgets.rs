//! Small widgets more than one panel draws: the resolution combo box (the open dialog's
//! and file panel's import settings, the paint panel's "Set R for all" and resolution tool).

use meshpaint_core::colors::layout::Resolution;

/// The resolutions the combo box offers: `R` = 1 … 64.
const LOG2_RANGE: std::ops::RangeInclusive<u32> = 0..=meshpaint_core::colors::layout::MAX_LOG2_RESOLUTION;

/// A combo box of resolutions 1 … 64 after `label` (its accessible name), editing
/// `resolution` in place.
pub fn resolution_combo(ui: &mut egui::Ui, label: &str, resolution: &mut Resolution) -> egui::Response {
    let label = ui.label(label);
    egui::ComboBox::from_id_salt(label.id)
        .selected_text(resolution.get().to_string())
        .show_ui(ui, |ui| {
            for log2 in LOG2_RANGE {
                if let Ok(r) = Resolution::from_log2(log2) {
                    ui.selectable_value(resolution, r, r.get().to_string());
                }
            }
        })
        .response
        .labelled_by(label.id)
}
