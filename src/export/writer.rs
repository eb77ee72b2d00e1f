//! [`Writer`]: an export's files. Frames are converted, encoded and written by a pool of
//! threads while the next frames render (each file is independent, so the bytes do not
//! depend on the order); a flipbook's cells come back to be placed in its atlases.

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, SyncSender, sync_channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

use super::encode::{self, Encoder};
use super::export_settings::{ExportSettings, Layout};
use super::frames::RawFrame;
use super::{ExportError, Sidecar};

/// One output frame, converted.
struct Encoded {
    j: u32,
    /// The colour, box-filtered small (seam statistics).
    thumb: Vec<[f32; 4]>,
    /// Flipbook: each pass's stored pixels, for the atlas; sequence: the colour (preview).
    passes: Vec<(&'static str, Vec<[f32; 4]>)>,
    /// Sequence: the files written under hidden names.
    pending: Vec<PathBuf>,
}

type Job = (u32, RawFrame, Arc<Encoder>);

/// The passes' files of one export.
pub(super) struct Writer {
    /// Shared with the threads; its motion scale is set before the first frame.
    encoder: Arc<Encoder>,
    /// Flipbook: one atlas per pass, in stored values (0..1 or linear).
    atlases: Vec<(&'static str, Vec<[f32; 4]>)>,
    /// The colour of the last sequence frame converted (the preview of a sequence).
    last_color: Option<Vec<[f32; 4]>>,
    /// Each output frame's thumbnail, once converted.
    thumbs: Vec<Vec<[f32; 4]>>,
    /// Sequence frames written under hidden names, not yet renamed.
    pending: Vec<PathBuf>,
    files: Vec<PathBuf>,
    jobs: Option<SyncSender<Job>>,
    done: Receiver<Result<Encoded, ExportError>>,
    workers: Vec<JoinHandle<()>>,
    in_flight: usize,
}

impl Drop for Writer {
    /// A cancelled or failed export leaves no frames under hidden names behind (the
    /// threads finish first).
    fn drop(&mut self) {
        self.jobs = None;
        for w in self.workers.drain(..) {
            let _ = w.join();
        }
        while let Ok(Ok(e)) = self.done.try_recv() {
            self.pending.extend(e.pending);
        }
        for p in &self.pending {
            let _ = std::fs::remove_file(p);
        }
    }
}

impl Writer {
    /// A writer into `settings.out_dir` (created) for `frames` frames of `preset`.
    pub fn new(settings: &ExportSettings, preset: &str, frames: u32) -> Result<Self, ExportError> {
        let dir = &settings.out_dir;
        std::fs::create_dir_all(dir).map_err(|e| ExportError::Write {
            path: dir.clone(),
            message: format!("{e} (choose another --out folder)"),
        })?;
        let (w, h) = settings.frame_size;
        let atlases = match settings.layout {
            Layout::Flipbook { cols, rows } => settings
                .passes
                .names()
                .into_iter()
                .map(|p| (p, vec![[0.0; 4]; (cols * w * rows * h) as usize]))
                .collect(),
            Layout::Sequence => Vec::new(),
        };
        let threads = std::thread::available_parallelism().map_or(2, |n| n.get().clamp(2, 8));
        let (jobs, queue) = sync_channel::<Job>(threads);
        let (report, done) = sync_channel(2 * threads + frames as usize);
        let queue = Arc::new(Mutex::new(queue));
        let workers = (0..threads)
            .map(|_| {
                let (queue, report) = (queue.clone(), report.clone());
                std::thread::spawn(move || work(&queue, &report))
            })
            .collect();
        Ok(Self {
            encoder: Arc::new(Encoder {
                settings: settings.clone(),
                stem: crate::preset::file_stem(preset),
                motion_scale: 1.0,
            }),
            atlases,
            last_color: None,
            thumbs: vec![Vec::new(); frames as usize],
            pending: Vec::new(),
            files: Vec::new(),
            jobs: Some(jobs),
            done,
            workers,
            in_flight: 0,
        })
    }

    /// The motion pass's scale (set before the first frame).
    pub fn set_motion_scale(&mut self, scale: f32) {
        Arc::make_mut(&mut self.encoder).motion_scale = scale;
    }

    /// The motion pass's scale.
    pub fn motion_scale(&self) -> f32 {
        self.encoder.motion_scale
    }

    /// Hands output frame `j` to the threads (waits when they are all busy).
    pub fn write_frame(&mut self, j: u32, frame: RawFrame) -> Result<(), ExportError> {
        let Some(jobs) = &self.jobs else {
            return Ok(());
        };
        jobs.send((j, frame, self.encoder.clone()))
            .map_err(|_| ExportError::Invalid("the export's writer threads stopped".into()))?;
        self.in_flight += 1;
        while let Ok(result) = self.done.try_recv() {
            self.take(result)?;
        }
        Ok(())
    }

    /// Places a converted frame (or returns its error).
    fn take(&mut self, result: Result<Encoded, ExportError>) -> Result<(), ExportError> {
        self.in_flight -= 1;
        let e = result?;
        if let Some(t) = self.thumbs.get_mut(e.j as usize) {
            *t = e.thumb;
        }
        self.pending.extend(e.pending);
        let (w, h) = self.encoder.settings.frame_size;
        for (name, pixels) in e.passes {
            let Layout::Flipbook { cols, .. } = self.encoder.settings.layout else {
                self.last_color = Some(pixels);
                continue;
            };
            let Some((_, atlas)) = self.atlases.iter_mut().find(|(n, _)| *n == name) else {
                continue;
            };
            let (cx, cy) = ((e.j % cols) * w, (e.j / cols) * h);
            let stride = (cols * w) as usize;
            for (y, row) in pixels.chunks(w as usize).enumerate() {
                let at = (cy as usize + y) * stride + cx as usize;
                atlas[at..at + w as usize].copy_from_slice(row);
            }
        }
        Ok(())
    }

    /// Waits for every frame handed over; returns each output frame's thumbnail.
    pub fn drain(&mut self) -> Result<&[Vec<[f32; 4]>], ExportError> {
        while self.in_flight > 0 {
            let result = self
                .done
                .recv()
                .map_err(|_| ExportError::Invalid("the export's writer threads stopped".into()))?;
            self.take(result)?;
        }
        Ok(&self.thumbs)
    }

    /// Writes the atlases (flipbook) or names the sequence's files, with frame `first`
    /// of the `frames` written as frame 0 (a loop's rotation), and the sidecar; returns
    /// every file written. Call [`Writer::drain`] first.
    pub fn finish(
        &mut self,
        sidecar: &Sidecar,
        frames: u32,
        first: u32,
    ) -> Result<Vec<PathBuf>, ExportError> {
        let enc = &self.encoder;
        let (w, h) = enc.settings.frame_size;
        let source = |k: u32| (k + first) % frames.max(1);
        let fail = |path: &PathBuf| {
            let path = path.clone();
            move |e: std::io::Error| ExportError::Write {
                path,
                message: e.to_string(),
            }
        };
        match enc.settings.layout {
            Layout::Flipbook { cols, rows } => {
                for (name, atlas) in &self.atlases {
                    let rotated = encode::rotate_cells(atlas, (w, h), cols, frames, source);
                    let path = enc.path(&format!("{}_{name}", enc.stem));
                    encode::write_image(
                        &path,
                        (cols * w, rows * h),
                        &rotated,
                        enc.settings.format,
                    )?;
                    self.files.push(path);
                }
            }
            Layout::Sequence => {
                for name in enc.settings.passes.names() {
                    for k in 0..frames {
                        let path = enc.path(&format!("{}_{name}_{k:04}", enc.stem));
                        std::fs::rename(enc.pending(name, source(k)), &path)
                            .map_err(fail(&path))?;
                        self.files.push(path);
                    }
                }
                self.pending.clear();
            }
        }
        let path = enc.settings.out_dir.join(format!("{}.json", enc.stem));
        crate::preset::write_atomic(&path, sidecar.to_json().as_bytes()).map_err(fail(&path))?;
        self.files.push(path);
        Ok(self.files.clone())
    }

    /// The colour atlas so far (flipbook) or the last frame converted (sequence), 8-bit.
    pub fn preview(&self) -> Option<image::RgbaImage> {
        let s = &self.encoder.settings;
        let (w, h) = s.frame_size;
        match s.layout {
            Layout::Flipbook { cols, rows } => {
                let atlas = &self.atlases.iter().find(|(n, _)| *n == "color")?.1;
                encode::preview_image((cols * w, rows * h), atlas, s.format)
            }
            Layout::Sequence => encode::preview_image((w, h), self.last_color.as_ref()?, s.format),
        }
    }
}

/// A writer thread: converts, encodes and writes frames until the queue closes.
fn work(queue: &Mutex<Receiver<Job>>, report: &SyncSender<Result<Encoded, ExportError>>) {
    loop {
        let job = match queue.lock() {
            Ok(q) => q.recv(),
            Err(_) => return,
        };
        let Ok((j, frame, encoder)) = job else {
            return;
        };
        if report.send(encode_frame(j, &frame, &encoder)).is_err() {
            return;
        }
    }
}

/// Output frame `j` converted: a sequence's files written under hidden names, or a
/// flipbook's cells returned.
fn encode_frame(j: u32, frame: &RawFrame, enc: &Encoder) -> Result<Encoded, ExportError> {
    let s = &enc.settings;
    let color = enc.color_pixels(frame);
    let mut out = Encoded {
        j,
        thumb: encode::thumbnail(&color, s.frame_size),
        passes: Vec::new(),
        pending: Vec::new(),
    };
    let mut color = Some(color);
    for name in s.passes.names() {
        let pixels = match (name, color.take()) {
            ("color", Some(c)) => c,
            _ => enc.pass_pixels(name, frame),
        };
        match s.layout {
            Layout::Sequence => {
                let path = enc.pending(name, j);
                encode::write_image(&path, s.frame_size, &pixels, s.format)?;
                out.pending.push(path);
                if name == "color" {
                    out.passes.push((name, pixels));
                }
            }
            Layout::Flipbook { .. } => out.passes.push((name, pixels)),
        }
    }
    Ok(out)
}
