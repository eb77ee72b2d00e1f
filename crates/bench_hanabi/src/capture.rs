//! The next frame's image, read back through Bevy's screenshot and written as a PNG.

use std::path::Path;

use bevy::prelude::*;

use crate::bevy_headless;

/// Renders frames until the screenshot of `target` arrives and writes it to `path`.
pub fn save(app: &mut App, target: &Handle<Image>, path: &Path) -> Result<(), String> {
    let image = bevy_headless::screenshot(app, target, 240)?;
    let dynamic = image
        .try_into_dynamic()
        .map_err(|e| format!("screenshot: {e}"))?;
    dynamic
        .to_rgba8()
        .save(path)
        .map_err(|e| format!("{}: {e}", path.display()))
}
