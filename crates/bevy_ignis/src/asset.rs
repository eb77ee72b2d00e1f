//! Presets as Bevy assets: [`IgnisPreset`] and the loader of `.ron` effect files, so that
//! `asset_server.load("effects/torch.ron")` works and Bevy's file watcher hot-reloads an
//! edited preset (a broken edit leaves the last good one playing, the error in the log).

use bevy::asset::io::Reader;
use bevy::asset::{AssetLoader, LoadContext};
use bevy::prelude::*;
use bevy::reflect::TypePath;

/// An ignis effect loaded from a preset file made in the ignis editor.
#[derive(Asset, TypePath, Clone, Debug)]
pub struct IgnisPreset {
    /// The effect.
    pub effect: ignis::Effect,
    /// The preset's path inside the asset folder (its sprites are relative to it).
    pub path: std::path::PathBuf,
}

/// Why a preset file did not load (the asset server logs it with the file's path).
#[derive(Debug, thiserror::Error)]
pub enum IgnisLoadError {
    /// The file could not be read.
    #[error("cannot read the preset: {0}")]
    Io(#[from] std::io::Error),
    /// The file is not a valid preset (the message names the line and field).
    #[error(transparent)]
    Preset(#[from] ignis::preset::PresetError),
    /// The preset parses but has impossible values.
    #[error("the effect is not valid: {0}")]
    Invalid(String),
}

/// Loads `.ron` preset files as [`IgnisPreset`]s.
#[derive(Default, TypePath)]
pub struct IgnisPresetLoader;

impl AssetLoader for IgnisPresetLoader {
    type Asset = IgnisPreset;
    type Settings = ();
    type Error = IgnisLoadError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        cx: &mut LoadContext<'_>,
    ) -> Result<IgnisPreset, IgnisLoadError> {
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).await?;
        let text = String::from_utf8_lossy(&bytes);
        let path = cx.path().path().to_path_buf();
        let effect = ignis::preset::parse_str(&text, &path.to_string_lossy())?;
        effect.validate().map_err(|errors| {
            let list: Vec<String> = errors.iter().map(ToString::to_string).collect();
            IgnisLoadError::Invalid(list.join("; "))
        })?;
        Ok(IgnisPreset { effect, path })
    }

    fn extensions(&self) -> &[&str] {
        &["ron"]
    }
}
