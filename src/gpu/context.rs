//! The one place that owns the wgpu instance, adapter, device and queue.

use std::sync::Arc;

/// Why no usable GPU device could be made.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("no GPU adapter found (install a Vulkan driver, e.g. Debian's mesa-vulkan-drivers): {0}")]
    NoAdapter(#[from] wgpu::RequestAdapterError),
    #[error("the GPU refused to create a device: {0}")]
    NoDevice(#[from] wgpu::RequestDeviceError),
    #[error("shader or pipeline {name} is invalid: {message}")]
    Shader { name: String, message: String },
    #[error("could not create a surface for the window: {0}")]
    Surface(#[from] wgpu::CreateSurfaceError),
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// A size past what the adapter allows (a texture edge, a buffer binding).
    #[error("{0}")]
    TooLarge(String),
    /// The scene's pool does not fit one buffer binding of the adapter.
    #[error("{pool} ({adapter})")]
    PoolTooLarge { pool: crate::gpu_pool::PoolTooLarge, adapter: String },
    /// wgpu reported a validation error while a frame was recorded.
    #[error("the GPU rejected the frame: {0}")]
    Validation(String),
}

/// Instance, adapter, device and queue, plus what the rest of the program
/// needs to know about them.
pub struct GpuContext {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    /// E.g. "llvmpipe (LLVM 15.0.6, 256 bits)" or "NVIDIA GeForce RTX 3080".
    pub adapter_name: String,
    /// GPU timestamp queries are available (else frame times are wall time).
    pub timestamps: bool,
}

impl GpuContext {
    /// A device without a window (render, replay, bench, tests).
    pub fn headless() -> Result<GpuContext, GpuError> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = wgpu::Backends::PRIMARY;
        let instance = wgpu::Instance::new(desc.with_env());
        pollster::block_on(Self::with_instance(instance, None))
    }

    /// An instance able to make surfaces for windows of this display.
    pub fn window_instance(display: Box<dyn wgpu::wgt::WgpuHasDisplayHandle>) -> wgpu::Instance {
        let mut desc = wgpu::InstanceDescriptor::new_with_display_handle(display);
        desc.backends = wgpu::Backends::PRIMARY;
        wgpu::Instance::new(desc.with_env())
    }

    /// Picks an adapter (compatible with `surface` if given) and opens a device.
    pub async fn with_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<GpuContext, GpuError> {
        let adapter = instance
            .request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                compatible_surface: surface,
                ..Default::default()
            })
            .await?;
        let (device, queue) = adapter.request_device(&Self::device_descriptor(&adapter)).await?;
        Ok(Self::from_parts(instance, adapter, device, queue))
    }

    /// The device octovox asks of `adapter`: timestamps where there are
    /// some, and the adapter's largest buffers, textures and bindings.
    pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
        let features = adapter.features() & wgpu::Features::TIMESTAMP_QUERY;
        let supported = adapter.limits();
        // Big scenes need big storage buffers (the dense grid of a 10 M-voxel
        // model is ~80 MB); ask for what the adapter has.
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: supported.max_storage_buffer_binding_size,
            max_buffer_size: supported.max_buffer_size,
            max_texture_dimension_2d: supported.max_texture_dimension_2d,
            // The path tracer binds nine storage buffers, one over WebGPU's
            // baseline of eight; desktop adapters have dozens.
            max_storage_buffers_per_shader_stage: supported.max_storage_buffers_per_shader_stage,
            ..wgpu::Limits::default()
        };
        wgpu::DeviceDescriptor {
            label: Some("octovox device"),
            required_features: features,
            required_limits: limits,
            ..Default::default()
        }
    }

    /// A context over a device opened elsewhere (the browser page's, by
    /// eframe) with [`GpuContext::device_descriptor`].
    pub fn from_parts(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
    ) -> GpuContext {
        let info = adapter.get_info();
        let adapter_name = info.name.clone();
        log::info!("GPU adapter: {adapter_name} ({:?}, {:?})", info.backend, info.device_type);
        device.on_uncaptured_error(Arc::new(|e: wgpu::Error| log::error!("wgpu: {e}")));
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        GpuContext { instance, adapter, device, queue, adapter_name, timestamps }
    }

    /// Compiles one of octovox's shader modules ([`super::shaders`]).
    pub fn module(&self, module: super::shaders::Module) -> Result<wgpu::ShaderModule, GpuError> {
        self.shader(module.label(), &module.source())
    }

    /// Compiles WGSL; a bad shader is an error value instead of a crash.
    pub fn shader(&self, name: &str, source: &str) -> Result<wgpu::ShaderModule, GpuError> {
        self.validated(name, |device| {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(name),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        })
    }

    /// Runs `create` inside a validation error scope, so that an invalid
    /// shader or pipeline is an error here rather than a pass that silently
    /// draws nothing later.
    pub fn validated<T>(&self, name: &str, create: impl FnOnce(&wgpu::Device) -> T) -> Result<T, GpuError> {
        validated_on(&self.device, name, create)
    }

    /// Runs `work` inside a validation error scope: any validation error
    /// while it records or submits (an oversized binding, a bad dispatch) is
    /// an error of the command instead of a line in the log and a blank image.
    pub fn checked<T>(&self, work: impl FnOnce() -> Result<T, GpuError>) -> Result<T, GpuError> {
        validated(&self.device, work)
    }

    /// Fails unless a `width`×`height` image fits the adapter's textures.
    pub fn check_image_size(&self, width: u32, height: u32) -> Result<(), GpuError> {
        let limit = self.device.limits().max_texture_dimension_2d;
        if width > limit || height > limit {
            return Err(GpuError::TooLarge(format!(
                "{width}x{height} pixels is larger than this GPU's {limit}x{limit} limit for an image ({})",
                self.adapter_name
            )));
        }
        Ok(())
    }

    /// Fails unless a storage buffer of `bytes` can be bound.
    pub fn check_binding(&self, what: &str, bytes: u64) -> Result<(), GpuError> {
        let limit = self.device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(GpuError::TooLarge(format!(
                "{what} needs a {bytes}-byte buffer; this GPU binds at most {limit} bytes ({})",
                self.adapter_name
            )));
        }
        Ok(())
    }

    /// Blocks until the GPU has finished all submitted work.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map(|_| ()).map_err(|e| GpuError::Readback(e.to_string()))
    }
}

/// [`GpuContext::validated`] on any thread (error scopes are per thread).
pub fn validated_on<T>(
    device: &wgpu::Device,
    name: &str,
    create: impl FnOnce(&wgpu::Device) -> T,
) -> Result<T, GpuError> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let created = create(device);
    match verdict(name, scope) {
        Some(err) => Err(GpuError::Shader { name: name.to_string(), message: err.to_string() }),
        None => Ok(created),
    }
}

/// A compute pipeline of `module`'s `entry` with override `constants`,
/// inside a validation scope (on any thread): every pass's kernels.
pub(super) fn compute_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
    constants: &[(&str, f64)],
    label: &str,
) -> Result<wgpu::ComputePipeline, GpuError> {
    validated_on(device, label, |device| {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(layout),
            module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                zero_initialize_workgroup_memory: false,
            },
            cache: None,
        })
    })
}

/// [`GpuContext::checked`] on a device handle, for work that needs the
/// context's owner mutably.
///
/// # Errors
/// The work's own error, or the first validation error it caused.
pub fn validated<T>(device: &wgpu::Device, work: impl FnOnce() -> Result<T, GpuError>) -> Result<T, GpuError> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let result = work();
    match verdict("a frame", scope) {
        Some(err) => Err(GpuError::Validation(err.to_string())),
        None => result,
    }
}

/// The error a scope caught, if any. The desktop waits for the device's
/// answer. WebGPU answers through a promise that the page's one thread
/// cannot wait on: there the answer is logged when it comes (`what` names
/// the work) and the work is taken as valid now.
#[cfg(not(target_arch = "wasm32"))]
fn verdict(_what: &str, scope: wgpu::ErrorScopeGuard) -> Option<wgpu::Error> {
    pollster::block_on(scope.pop())
}

#[cfg(target_arch = "wasm32")]
fn verdict(what: &str, scope: wgpu::ErrorScopeGuard) -> Option<wgpu::Error> {
    let what = what.to_string();
    let answer = scope.pop();
    wasm_bindgen_futures::spawn_local(async move {
        if let Some(err) = answer.await {
            log::error!("wgpu: {what}: {err}");
        }
    });
    None
}
