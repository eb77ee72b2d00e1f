//! The next frame's image, read back through Bevy's screenshot and written as a PNG.

use std::path::Path;
use std::sync::{Arc, Mutex};

use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};

/// Renders frames until the screenshot of `target` arrives and writes it to `path`.
pub fn save(app: &mut App, target: &Handle<Image>, path: &Path) -> Result<(), String> {
    let slot: Arc<Mutex<Option<Image>>> = Arc::default();
    let out = slot.clone();
    app.world_mut()
        .spawn(Screenshot::image(target.clone()))
        .observe(move |shot: On<ScreenshotCaptured>| {
            if let Ok(mut s) = out.lock() {
                *s = Some(shot.image.clone());
            }
        });
    for _ in 0..240 {
        app.update();
        let taken = slot.lock().ok().and_then(|mut s| s.take());
        if let Some(image) = taken {
            let dynamic = image
                .try_into_dynamic()
                .map_err(|e| format!("screenshot: {e}"))?;
            return dynamic
                .to_rgba8()
                .save(path)
                .map_err(|e| format!("{}: {e}", path.display()));
        }
    }
    Err("no screenshot arrived in 240 frames".into())
}
