//! Embedding ignis: a plain winit + wgpu program draws its own scene (`scene.rs`: a
//! ground, boxes and posts with its own depth buffer, lighting and tonemap) and plays
//! three torches — instances of `presets/torch.ron` — and a campfire inside its own
//! render pass. Everything ignis-specific is in this file.
//!
//! `cargo run --release --example embed` (drag to orbit). Headless-testable:
//! `embed --frames 120 --screenshot shot.png` renders 120 frames of 1/60 s each and
//! saves the last one.

mod scene;

use std::sync::Arc;
use std::time::Instant;

use glam::{Mat4, Vec3, vec3};
use ignis::{Camera, HostTargets, Player, PlayerSettings, PointLight, SceneLighting};
use scene::Scene;
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

type Error = Box<dyn std::error::Error>;

/// The host's light strength per unit of the campfire's light power (its scene's units).
const FIRE_LIGHT_PER_UNIT: f32 = 7.5;
/// The host's moon and sky (`scene.wgsl` lights its geometry with the same).
const MOON_DIRECTION: Vec3 = vec3(-0.3, 1.0, 0.4);
const MOON_RGB: [f32; 3] = [0.04, 0.05, 0.09];
const SKY_RGB: [f32; 3] = [0.015, 0.015, 0.025];

fn main() -> Result<(), Error> {
    let mut app = App {
        frames: None,
        screenshot: None,
        host: None,
        result: Ok(()),
    };
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--frames" => app.frames = args.next().and_then(|n| n.parse().ok()),
            "--screenshot" => app.screenshot = args.next(),
            other => return Err(format!("unknown argument {other:?}").into()),
        }
    }
    EventLoop::new()?.run_app(&mut app)?;
    app.result
}

struct App {
    frames: Option<u32>,
    screenshot: Option<String>,
    host: Option<Host>,
    result: Result<(), Error>,
}

/// The host program: its window and scene, and one ignis player per effect.
struct Host {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    device: wgpu::Device,
    queue: wgpu::Queue,
    scene: Scene,
    torches: Player,
    campfire: Player,
    /// The campfire's instance (its light lights the scene).
    fire: ignis::InstanceId,
    /// The torches' instances (their lights light the campfire's smoke).
    torch_ids: Vec<ignis::InstanceId>,
    frame: u32,
    last: Instant,
    yaw: f32,
    dragging: bool,
}

impl Host {
    fn new(event_loop: &ActiveEventLoop) -> Result<Self, Error> {
        let size = winit::dpi::PhysicalSize::new(1280, 720);
        let attributes = Window::default_attributes().with_title("ignis — embedded");
        let window = Arc::new(event_loop.create_window(attributes.with_inner_size(size))?);
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
                Box::new(event_loop.owned_display_handle()),
            ));
        let surface = instance.create_surface(window.clone())?;
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
            &instance,
            Some(&surface),
        ))?;
        // ignis: the limits its players need (compute, storage buffers), named in the error
        // if the adapter lacks one.
        let (device, queue) =
            pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
                required_limits: ignis::required_limits().using_resolution(adapter.limits()),
                ..Default::default()
            }))?;
        let size = window.inner_size();
        let mut config = (surface.get_default_config(&adapter, size.width, size.height))
            .ok_or("the adapter cannot present to this window")?;
        config.format = config.format.add_srgb_suffix();
        config.usage |= wgpu::TextureUsages::COPY_SRC; // for --screenshot
        surface.configure(&device, &config);

        // ignis: one player per effect, drawing into the host's HDR target and testing
        // against its depth; then as many instances as the level has.
        let settings = PlayerSettings {
            depth_format: Some(scene::DEPTH),
            asset_dir: Some("presets".into()),
            ..PlayerSettings::new(scene::HDR)
        };
        let torch = ignis::preset::load("presets/torch.ron".as_ref())?;
        let mut torches = Player::new(&device, &queue, &torch, settings.clone())?;
        let fire = ignis::preset::load("presets/campfire.ron".as_ref())?;
        let mut campfire = Player::new(&device, &queue, &fire, settings)?;
        let posts = [
            vec3(-2.5, 0.0, -1.0),
            vec3(2.5, 0.0, -1.0),
            vec3(0.0, 0.0, -3.0),
        ];
        let mut torch_ids = Vec::new();
        for (seed, post) in posts.iter().enumerate() {
            torch_ids.push(torches.add_instance(Mat4::from_translation(*post), seed as u32 + 1)?);
        }
        let fire = campfire.add_instance(Mat4::IDENTITY, 7)?;
        // ignis: the campfire's own light (estimated from its flames) lights the scene,
        // and each effect's light lights the other's smoke.
        campfire.set_light_estimate(true);
        torches.set_light_estimate(true);

        let scene = Scene::new(
            &device,
            config.format,
            (config.width, config.height),
            &posts,
        );
        Ok(Self {
            window,
            surface,
            config,
            device,
            queue,
            scene,
            torches,
            campfire,
            fire,
            torch_ids,
            frame: 0,
            last: Instant::now(),
            yaw: 0.6,
            dragging: false,
        })
    }

    fn render(&mut self, dt_secs: f64, screenshot: Option<&str>) -> Result<(), Error> {
        let wgpu::CurrentSurfaceTexture::Success(frame) = self.surface.get_current_texture() else {
            return Ok(()); // skipped: the next frame tries again
        };
        let size = (self.config.width, self.config.height);
        let eye = Vec3::new(self.yaw.sin() * 7.0, 3.0, self.yaw.cos() * 7.0);
        let view = glam::camera::rh::view::look_at_mat4(eye, vec3(0.0, 0.8, -0.8), Vec3::Y);
        let aspect = size.0 as f32 / size.1 as f32;
        let proj = glam::camera::rh::proj::directx::perspective(0.8, aspect, 0.1, 100.0);

        // ignis, 1: advance the clocks (a carried torch would get set_transform here).
        self.torches.advance(dt_secs);
        self.campfire.advance(dt_secs);

        let mut enc = self.device.create_command_encoder(&Default::default());
        // The fire's light, as the campfire's flames give it (two frames behind them).
        let fire = self
            .campfire
            .effect_light(self.fire)
            .map_or([0.0, 0.5, 0.0, 0.0], |l| {
                let p = l.position;
                [p.x, p.y, p.z, l.power * FIRE_LIGHT_PER_UNIT]
            });
        (self.scene).draw_opaque(&self.queue, &mut enc, proj * view, fire);
        // ignis: the smoke is lit by the host's moon and sky and by the other effect's
        // fire (its own flames light it already).
        let torch_lights = (self.torch_ids.iter())
            .filter_map(|id| self.torches.effect_light(*id))
            .collect();
        let campfire_light = self.campfire.effect_light(self.fire).into_iter().collect();
        self.campfire.set_lighting(Some(night(torch_lights)));
        self.torches.set_lighting(Some(night(campfire_light)));
        // ignis, 2: the simulation and sorting, after the opaque pass wrote the depth
        // that the soft edges sample.
        let camera = Camera::new(view, proj, size);
        let depth = Some(&self.scene.depth);
        self.torches.record(&mut enc, &camera, depth)?;
        self.campfire.record(&mut enc, &camera, depth)?;
        {
            // ignis, 3: the particles in a pass on the host's views (depth read-only).
            let targets = HostTargets {
                color: &self.scene.hdr,
                resolve_target: None,
                depth,
            };
            let mut pass = targets.begin_pass(&mut enc);
            self.torches.draw(&mut pass);
            self.campfire.draw(&mut pass);
        }
        let target = frame.texture.create_view(&Default::default());
        self.scene.tonemap(&mut enc, &target);
        let shot = screenshot.map(|path| {
            (
                path,
                scene::read_back(&self.device, &mut enc, &frame.texture),
            )
        });
        self.queue.submit([enc.finish()]);
        self.window.pre_present_notify();
        self.queue.present(frame);
        self.frame += 1;
        match shot {
            Some((path, copy)) => {
                scene::save_png(&self.device, copy, size, self.config.format, path)
            }
            None => Ok(()),
        }
    }
}

/// The host's moon and sky, and the effect lights of `fires` as point lights (in the
/// host's units: `FIRE_LIGHT_PER_UNIT`, reaching 6 m).
fn night(fires: Vec<ignis::EffectLight>) -> SceneLighting {
    let point_lights = fires
        .iter()
        .map(|l| PointLight {
            position: l.position,
            color: l.rgb_power.map(|c| c * FIRE_LIGHT_PER_UNIT),
            range_m: 6.0,
        })
        .collect();
    SceneLighting {
        sun_direction: MOON_DIRECTION,
        sun_color: MOON_RGB,
        ambient: SKY_RGB,
        point_lights,
        own_light: 1.0,
        glow: 1.0,
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.host.is_none() {
            match Host::new(event_loop) {
                Ok(host) => self.host = Some(host),
                Err(e) => (self.result, _) = (Err(e), event_loop.exit()),
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(host) = self.host.as_mut() else {
            return;
        };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                (host.config.width, host.config.height) = (size.width.max(1), size.height.max(1));
                host.surface.configure(&host.device, &host.config);
                let size = (host.config.width, host.config.height);
                host.scene.resize(&host.device, size);
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                host.dragging = state == ElementState::Pressed;
            }
            WindowEvent::CursorMoved { position, .. } if host.dragging => {
                host.yaw = position.x as f32 * 0.01;
            }
            WindowEvent::RedrawRequested => {
                // Scripted runs step exactly 1/60 s a frame: their frames are reproducible.
                let dt = match self.frames {
                    Some(_) => 1.0 / 60.0,
                    None => host.last.elapsed().as_secs_f64(),
                };
                host.last = Instant::now();
                let last = self.frames.is_some_and(|n| host.frame + 1 >= n);
                let shot = self.screenshot.as_deref().filter(|_| last);
                if let Err(e) = host.render(dt, shot) {
                    (self.result, _) = (Err(e), event_loop.exit());
                } else if last {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(host) = &self.host {
            host.window.request_redraw();
        }
    }
}
