//! The editor's panels: each a type that owns its state and draws itself with a `ui`
//! method, reading what it needs of the editor as arguments and returning the
//! [`Command`](crate::app::command::Command)s it wants carried out (never reaching into the
//! editor).
//!
//! | panel | file | owns |
//! |---|---|---|
//! | [`MenuBar`] | [`menu`] | nothing |
//! | [`StatusLine`] | [`status_line`] | nothing (shows the editor's status) |
//! | [`FilePanel`] | [`file`] | the file dialog, the directory dialogs start in |
//! | [`ExportPanel`] | [`export`] | File → Export…'s choices, the UV check, the cost shown |
//! | [`ImportSettings`] | `import_settings` (app level: the file dialog shows it too) | the resolution choice for opened meshes |
//! | [`AutosavePanel`] | [`autosave`] | autosave settings, timer and recovery offer |
//! | [`ViewPanel`] | [`view`] (the heat map's legend: [`heat_legend`]) | view settings, the last PSNR |
//! | [`PaintPanel`] | [`paint`] (its sections: [`color`], [`presets`]) | the brush, the colour wheel and hex field, the recent colours, the brush presets, the resolution of "Set R for all" |
//! | [`OptimizePanel`] | [`optimize`] | Optimize's error bound |
//! | [`UndoPanel`] | [`undo`] | nothing (shows the document's history) |
//! | [`ScenePanel`] | [`scene`] | "Redraw continuously" |
//! | [`HelpWindow`] | [`help`] | whether it is open |
//! | [`UnsavedPrompt`] | [`unsaved`] | the action waiting for "save changes first?" |
//! | [`ViewportArea`] | [`viewport`] | nothing (the editor records its area) |

pub mod autosave;
pub mod color;
pub mod export;
pub mod file;
pub mod heat_legend;
pub mod help;
pub mod menu;
pub mod optimize;
pub mod paint;
pub mod presets;
pub mod scene;
pub mod status_line;
pub mod undo;
pub mod unsaved;
pub mod view;
pub mod viewport;

pub use crate::app::import_settings::ImportSettings;
pub use autosave::AutosavePanel;
pub use export::{ExportContext, ExportPanel};
pub use file::FilePanel;
pub use help::HelpWindow;
pub use menu::MenuBar;
pub use optimize::OptimizePanel;
pub use paint::{PaintPanel, PaintPanelContext};
pub use scene::{SceneContext, ScenePanel};
pub use status_line::StatusLine;
pub use undo::{LastStroke, UndoPanel};
pub use unsaved::UnsavedPrompt;
pub use view::{ViewContext, ViewPanel};
pub use viewport::{ViewportArea, ViewportContext};

/// Width of the side panel, points.
pub const SIDE_PANEL_WIDTH: f32 = 250.0;

/// Every panel of the editor.
#[derive(Debug, Default)]
pub struct Panels {
    /// File, View, Help menus.
    pub menu: MenuBar,
    /// Mode, message, progress.
    pub status_line: StatusLine,
    /// Open, save, export and the file dialog.
    pub file: FilePanel,
    /// How meshes opened next get their face resolutions (the open dialog's choice).
    pub import: ImportSettings,
    /// File → Export….
    pub export: ExportPanel,
    /// Autosave settings and the recovery offer.
    pub autosave: AutosavePanel,
    /// Filter, shading, overlays, what is shown.
    pub view: ViewPanel,
    /// Paint mode, brush and paint commands.
    pub paint: PaintPanel,
    /// Optimize.
    pub optimize: OptimizePanel,
    /// Undo / redo and the undo memory.
    pub undo: UndoPanel,
    /// Statistics.
    pub scene: ScenePanel,
    /// The shortcut help window.
    pub help: HelpWindow,
    /// "Save changes first?"
    pub unsaved: UnsavedPrompt,
    /// The 3D view's area.
    pub viewport: ViewportArea,
}
