//! The editor's side of the settings file ([`super::settings`]): what it remembers is read
//! from the panels into one [`Settings`], and written back into them. The window loads the
//! file once before the first document opens and saves it whenever the remembered state has
//! changed and no pointer button is held (so a drag writes once, at its end).

use std::path::PathBuf;

use super::editor::Editor;
use super::settings::{self, Settings, SettingsFile};
use super::state::Severity;

impl Editor {
    /// The remembered state, as the panels hold it now.
    pub fn settings(&self) -> Settings {
        let view = &self.panels.view.settings;
        Settings {
            presets: self.panels.paint.presets.presets.clone(),
            recent_colors: self.panels.paint.recent_colors.clone(),
            up_axis: self.panels.import.up_axis,
            zoom_to_cursor: view.zoom_to_cursor,
            shading: view.shading,
        }
    }

    /// Puts `settings` into the panels.
    pub fn apply_settings(&mut self, settings: Settings) {
        self.panels.paint.presets.presets = settings.presets;
        self.panels.paint.recent_colors = settings.recent_colors;
        self.panels.import.up_axis = settings.up_axis;
        self.panels.view.settings.zoom_to_cursor = settings.zoom_to_cursor;
        self.panels.view.settings.shading = settings.shading;
    }

    /// Reads the settings file at `path` into the panels (nothing there: the defaults stay).
    /// A file that cannot be used leaves the defaults, reports why on the status line (and
    /// again once the first document opened), and is not overwritten until a setting changes.
    pub fn load_settings(&mut self, path: Option<PathBuf>) {
        let loaded = path.as_deref().map(settings::load).transpose();
        self.settings_file = SettingsFile { path, saved: None, problem: None };
        match loaded {
            Ok(Some(Some(settings))) => self.apply_settings(settings),
            Ok(_) => {}
            Err(problem) => {
                self.set_status(Severity::Warning, problem.clone());
                self.settings_file.problem = Some(problem);
            }
        }
        self.settings_file.saved = Some(self.settings());
    }

    /// Writes the settings file when the remembered state changed since it was last read or
    /// written, unless `pointer_down` (a drag is still changing it). Returns whether it wrote.
    pub fn save_settings_if_changed(&mut self, pointer_down: bool) -> bool {
        let Some(path) = self.settings_file.path.clone() else {
            return false;
        };
        let current = self.settings();
        if pointer_down || self.settings_file.saved.as_ref() == Some(&current) {
            return false;
        }
        let result = settings::save(&path, &current);
        // Written or not, it is not tried again until something changes again.
        self.settings_file.saved = Some(current);
        match result {
            Ok(()) => true,
            Err(message) => {
                self.set_status(Severity::Warning, format!("Settings not saved: {message}"));
                false
            }
        }
    }
}
