//! A headless wgpu device with the features the renderer uses, and validation-error capture.

use std::sync::{Arc, Mutex};

pub use crate::error::RenderError;

/// How colour layers are stored on the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ColourFormat {
    /// BC7 on GPUs, RGBA8 on CPU rasterisers (see [`GpuContext::use_bc7`]).
    #[default]
    Auto,
    /// BC7 (1 byte per texel) where the device has BC textures, else RGBA8.
    Bc7,
    /// RGBA8 (4 bytes per texel).
    Rgba8,
}

/// Device, queue and the validation errors wgpu reported so far.
pub struct GpuContext {
    /// The adapter's description (name, backend, type).
    pub adapter_info: wgpu::AdapterInfo,
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    errors: Arc<Mutex<Vec<String>>>,
}

impl GpuContext {
    /// Open the first adapter wgpu's default instance offers, preferring a high-performance
    /// one, with timestamp queries and BC textures where available and the adapter's own
    /// limits. Reads no environment variable; a front end that wants wgpu's (`WGPU_BACKEND`,
    /// ...) passes `InstanceDescriptor::new_without_display_handle_from_env()` to
    /// [`Self::headless_with`].
    pub fn headless() -> Result<Self, RenderError> {
        Self::headless_with(wgpu::InstanceDescriptor::new_without_display_handle())
    }

    /// [`Self::headless`] with the host's instance options.
    pub fn headless_with(desc: wgpu::InstanceDescriptor) -> Result<Self, RenderError> {
        let instance = wgpu::Instance::new(desc);
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| RenderError::NoAdapter(e.to_string()))?;
        Self::from_adapter(&adapter)
    }

    /// Open a device on a given adapter (for windows with a surface).
    pub fn from_adapter(adapter: &wgpu::Adapter) -> Result<Self, RenderError> {
        let wanted = wgpu::Features::TIMESTAMP_QUERY
            | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
            | wgpu::Features::TEXTURE_COMPRESSION_BC
            | wgpu::Features::INDIRECT_FIRST_INSTANCE
            | wgpu::Features::PIPELINE_STATISTICS_QUERY;
        let features = adapter.features() & wanted;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("forest"),
            required_features: features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| RenderError::Device(e.to_string()))?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().unwrap().push(e.to_string());
        }));
        Ok(Self {
            adapter_info: adapter.get_info(),
            device,
            queue,
            errors,
        })
    }

    /// Wrap a device and queue the application already has (its error handler is left alone,
    /// so [`Self::take_errors`] reports nothing; the device should have the adapter's limits
    /// for large scenes, and `TIMESTAMP_QUERY` for pass times).
    pub fn from_device(
        adapter_info: wgpu::AdapterInfo,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> Self {
        Self {
            adapter_info,
            device,
            queue,
            errors: Arc::new(Mutex::new(Vec::new())),
        }
    }

    /// Validation and out-of-memory errors reported since the last call (drained).
    pub fn take_errors(&self) -> Vec<String> {
        let _ = self.device.poll(wgpu::PollType::wait_indefinitely());
        std::mem::take(&mut *self.errors.lock().unwrap())
    }

    /// Fail with [`RenderError::Gpu`] if wgpu has reported errors since the last check
    /// (drained), without waiting for the GPU: for frame loops.
    pub fn check_reported_errors(&self) -> Result<(), RenderError> {
        let errors = std::mem::take(&mut *self.errors.lock().unwrap_or_else(|e| e.into_inner()));
        if errors.is_empty() {
            Ok(())
        } else {
            Err(RenderError::Gpu(errors))
        }
    }

    /// Fail with [`RenderError::Gpu`] if errors were reported since the last call (drained).
    pub fn check_errors(&self) -> Result<(), RenderError> {
        let errors = self.take_errors();
        if errors.is_empty() {
            Ok(())
        } else {
            Err(RenderError::Gpu(errors))
        }
    }

    /// Submit `enc` (which copies into the `MAP_READ` buffer `staging`), wait, and return the
    /// buffer's bytes. Read-backs are for tests, statistics and screenshots, never per frame.
    pub fn submit_and_read(&self, enc: wgpu::CommandEncoder, staging: &wgpu::Buffer) -> Vec<u8> {
        self.queue.submit([enc.finish()]);
        staging.map_async(wgpu::MapMode::Read, .., |r| {
            r.expect("map a read-back buffer")
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the device answers");
        let bytes = staging.get_mapped_range(..).expect("mapped").to_vec();
        staging.unmap();
        bytes
    }

    /// Copy the first `size` bytes of `src` (a `COPY_SRC` buffer) back to the CPU; waits.
    pub fn read_buffer(&self, src: &wgpu::Buffer, size: u64) -> Vec<u8> {
        let size = size.max(4).next_multiple_of(4).min(src.size());
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(src, 0, &staging, 0, size);
        self.submit_and_read(enc, &staging)
    }

    /// Whether the device can sample BC textures.
    pub fn has_bc(&self) -> bool {
        self.device
            .features()
            .contains(wgpu::Features::TEXTURE_COMPRESSION_BC)
    }

    /// Whether colour layers are uploaded as BC7 for `choice`.
    ///
    /// [`ColourFormat::Auto`]: BC7 when the device has BC textures and is not a CPU rasteriser
    /// (lavapipe decodes BC7 in software on every sample, which made drawing ~10× slower
    /// there).
    pub fn use_bc7(&self, choice: ColourFormat) -> bool {
        match choice {
            ColourFormat::Bc7 => self.has_bc(),
            ColourFormat::Rgba8 => false,
            ColourFormat::Auto => {
                self.has_bc() && self.adapter_info.device_type != wgpu::DeviceType::Cpu
            }
        }
    }
}
