//! The internals the integration tests in `tests/` (and the Bevy plugin's tests) check, in
//! the crate's own layout: the GPU context and the state's records, the simulation beside
//! its CPU reference, the shader library, the renderer's helpers and the editor's UI
//! functions. Not part of the API: nothing here is stable, and a new entry is a conscious
//! choice (a test that needs more adds it here, by name).

/// The effect model's baked curves, as the GPU reads them (`effect::curve`).
pub mod effect {
    pub use crate::effect::curve::{CURVE_WIDTH, lookup_blend};
}

/// GPU helpers and the state's records (`gpu`).
pub mod gpu {
    pub use crate::gpu::{
        AdapterProfile, GpuContext, GpuError, INT64_ATOMICS, TextureReadback, texture_2d,
    };

    /// The GPU records: particle state, parameters, uniforms.
    pub mod types {
        pub use crate::gpu::types::{
            Birth, CameraUniform, LookUniform, PackedParticle, Particle, SimParams, ToneUniform,
        };
    }

    /// Timestamp queries.
    pub mod timer {
        pub use crate::gpu::timer::{GpuTimer, PassTimer};
    }
}

/// The shader library and its composed sources (`shaders`).
pub mod shaders {
    pub use crate::shaders::{
        DEPTH_IO, EMBEDDED, ENTRY_FILES, EVENTS_IO, PACKED_STATE_IO, PARAMS_INSTANCED,
        SPLAT_ACCUM64, ShaderError, ShaderLibrary, TINY_STATE_IO, TRAIL_IO,
    };
}

/// The random streams (`rng`).
pub mod rng {
    pub use crate::rng::{emitter_salt, hash_cell3, rand_block, spawn_key, unorm, unorm4};
}

/// The simulation, its planner and its CPU reference (`sim`).
pub mod sim {
    pub use crate::sim::{CpuSim, EffectPlanner, GpuSim, Modules, SimError, Stepper};

    /// Instances batched into one pool.
    pub mod batch {
        pub use crate::sim::batch::batchable;
    }

    /// The CPU reference of the update.
    pub mod cpu_reference {
        pub use crate::sim::cpu_reference::{
            Forces, curl_noise, evaluate_stateless, spawn_particle,
        };
    }

    /// Events: rules, records, the scan and its CPU mirror.
    pub mod event_scan {
        pub use crate::sim::event_scan::{
            EventRecord, EventRule, EventSpawn, ScanConfig, child_key, event_of, rules_of,
            scan_events, step_cap,
        };
    }

    /// Reading GPU buffers back.
    pub mod gpu_sim {
        pub use crate::sim::gpu_sim::map_read;
    }

    /// Trail rings and ribbon links.
    pub mod trails {
        pub use crate::sim::trails::{Link, trail_indices};
    }
}

/// The renderer's passes and helpers (`render`).
pub mod render {
    pub use crate::render::tiles::TileStages;
    pub use crate::render::{OrbitCamera, TilePass};

    /// Heat haze's distortion target and refraction.
    pub mod haze {
        pub use crate::render::haze::HazePass;
    }

    /// The billboards' pipeline variants.
    pub mod variant {
        pub use crate::render::variant::{LookVariant, StateVariant};
    }

    /// The looks' uniform.
    pub mod frame {
        pub use crate::render::frame::look_uniform;
    }

    /// Colour ramps, curves and flipbooks baked for the GPU.
    pub mod look_bake {
        pub use crate::render::look_bake::{
            RAMP_WIDTH, bake_look_curves, bake_ramp, flipbook_frame, look_curve_params,
            sample_gradient,
        };
    }

    /// The six-way maps ignis makes.
    pub mod sixway_maps {
        pub use crate::render::sixway_maps::{
            EXTINCTION, PUFF_SEED, combined, puff, puff_density, puff_sheet,
        };
    }

    /// The billboards' cut to their sprite's visible part.
    pub mod sprite_trim {
        pub use crate::render::sprite_trim::{OCTAGON_SHARE, Trim, trim};
    }

    /// The GPU sort.
    pub mod sort {
        pub use crate::render::sort::SortPass;
    }

    /// Sprite images.
    pub mod sprites {
        pub use crate::render::sprites::{SpriteLibrary, TRIM_THRESHOLD, coverage, generate};
    }

    /// The composite's bloom.
    pub mod bloom {
        pub use crate::render::bloom::BloomPass;
    }

    /// The composite's tonemap.
    pub mod tonemap {
        pub use crate::render::tonemap::TonemapPass;
    }

    /// The tile rasteriser's limits.
    pub mod tiles {
        pub use crate::render::tiles::STORAGE_BUFFERS_NEEDED;
    }
}

/// A player and its composite with no window (`headless`, `composite`).
pub mod headless {
    pub use crate::headless::Headless;
}

/// The editor's composite: HDR target, bloom, tonemap (`composite`).
pub mod composite {
    pub use crate::composite::Composite;
}

/// Watching files and reloading shaders (`hot_reload`).
#[cfg(feature = "editor")]
pub mod hot_reload {
    pub use crate::hot_reload::{FileWatcher, ReloadReport, ShaderReloader, wgsl_names};
}

/// The accuracy bench's scenes (`bench::accuracy`).
#[cfg(feature = "editor")]
pub mod bench {
    /// Scenes with closed forms and the fixed-step hashes.
    pub mod accuracy {
        pub use crate::bench::accuracy::{
            Scene, exact_state, fixed_step_hashes, scene_emitter, setup_scene,
        };
    }
}

/// The editor's UI functions and state, driven by tests without a window (`editor`).
#[cfg(feature = "editor")]
pub mod editor {
    pub use crate::editor::EditorState;

    /// The editor's state.
    pub mod state {
        pub use crate::editor::state::{PendingAction, Playback, with_mouse_collider};
    }

    /// The side panel's sections, the timeline and the viewport.
    pub mod panel {
        pub use crate::editor::panel::panel_ui;

        /// The curve editor.
        pub mod curve_editor {
            pub use crate::editor::panel::curve_editor::{View, plot_area};
        }

        /// The export section.
        pub mod export_ui {
            pub use crate::editor::panel::export_ui::drive;
        }

        /// The Look section.
        pub mod look_ui {
            pub use crate::editor::panel::look_ui::SIZE;
        }

        /// The Measure section.
        pub mod measure_ui {
            pub use crate::editor::panel::measure_ui::drive;
        }

        /// The timeline.
        pub mod timeline {
            pub use crate::editor::panel::timeline::{play, span_secs, timeline_ui};
        }

        /// The viewport.
        pub mod viewport {
            pub use crate::editor::panel::viewport::viewport_ui;
        }
    }

    /// The window's machinery.
    pub mod window {
        /// The retained window.
        pub mod retained {
            pub use crate::editor::window::retained::{Repaint, RetainedUi};
        }

        /// Screenshots.
        pub mod screenshot {
            pub use crate::editor::window::screenshot::{Screenshot, read_back};
        }

        /// egui's painters.
        pub mod ui_painter {
            pub use crate::editor::window::ui_painter::UiPainter;
        }
    }
}
