//! Two GPU timestamps around a frame's render graph: one recorded before every system
//! that renders (`RenderGraphSystems::Begin`), one after the cameras (`camera_driver`),
//! so that what lies between is hanabi's simulation and every camera's passes. Read back
//! after each `app.update()` (the render world runs on the main thread).

use std::sync::Arc;

use bevy::core_pipeline::schedule::camera_driver;
use bevy::prelude::*;
use bevy::render::RenderApp;
use bevy::render::renderer::{
    RenderContext, RenderDevice, RenderGraph, RenderGraphSystems, RenderQueue,
};

/// The query set and its buffers, shared by the render world (which writes them) and the
/// main world (which reads them).
#[derive(Resource, Clone)]
pub struct Stamps(Arc<Inner>);

struct Inner {
    set: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    period_ns: f32,
    device: wgpu::Device,
}

/// Adds [`Stamps`] and the two systems that write them.
pub struct StampsPlugin;

impl Plugin for StampsPlugin {
    fn build(&self, _app: &mut App) {}

    fn finish(&self, app: &mut App) {
        let render_app = app.sub_app_mut(RenderApp);
        let device = render_app
            .world()
            .resource::<RenderDevice>()
            .wgpu_device()
            .clone();
        let period_ns = render_app
            .world()
            .resource::<RenderQueue>()
            .get_timestamp_period();
        let buffer = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        let stamps = Stamps(Arc::new(Inner {
            set: device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("bench_hanabi stamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolve: buffer(
                "bench_hanabi resolve",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            read: buffer(
                "bench_hanabi read",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
            period_ns,
            device,
        }));
        render_app.insert_resource(stamps.clone());
        render_app.add_systems(
            RenderGraph,
            (
                begin.in_set(RenderGraphSystems::Begin),
                end.in_set(RenderGraphSystems::Render).after(camera_driver),
            ),
        );
        app.insert_resource(stamps);
    }
}

/// A timestamp at `index`, written by an empty compute pass.
fn stamp(enc: &mut wgpu::CommandEncoder, set: &wgpu::QuerySet, index: u32) {
    drop(enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("bench_hanabi stamp"),
        timestamp_writes: Some(wgpu::ComputePassTimestampWrites {
            query_set: set,
            beginning_of_pass_write_index: Some(index),
            end_of_pass_write_index: None,
        }),
    }));
}

fn begin(mut ctx: RenderContext, stamps: Res<Stamps>) {
    stamp(ctx.command_encoder(), &stamps.0.set, 0);
}

fn end(mut ctx: RenderContext, stamps: Res<Stamps>) {
    let s = &stamps.0;
    let enc = ctx.command_encoder();
    stamp(enc, &s.set, 1);
    enc.resolve_query_set(&s.set, 0..2, &s.resolve, 0);
    enc.copy_buffer_to_buffer(&s.resolve, 0, &s.read, 0, 16);
}

impl Stamps {
    /// The last rendered frame's time between the two stamps, in milliseconds (waits for
    /// the GPU).
    pub fn read_ms(&self) -> Option<f64> {
        let s = &self.0;
        let slice = s.read.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        s.device.poll(wgpu::PollType::wait_indefinitely()).ok()?;
        let ticks: [u64; 2] = {
            let bytes = slice.get_mapped_range().ok()?;
            let mut t = [0u64; 2];
            for (i, c) in bytes.chunks_exact(8).take(2).enumerate() {
                t[i] = u64::from_le_bytes(c.try_into().ok()?);
            }
            t
        };
        s.read.unmap();
        let dt = ticks[1].checked_sub(ticks[0])?;
        Some(dt as f64 * f64::from(s.period_ns) / 1e6)
    }
}
