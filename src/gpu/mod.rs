//! The WGSL port run on a GPU with wgpu (feature `gpu`): a device, and the compute bake of a
//! tiling-and-blending texture that `tessera bake --gpu` and `tessera gpu-check` use. The
//! shaders themselves are [`crate::shader`]'s, which needs no GPU.

mod bake;
mod synthesis;
mod view;

pub use bake::GpuBake;
pub use view::GpuView;

/// Why the GPU could not be used.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct GpuError(pub String);

impl From<crate::shader::ShaderError> for GpuError {
    fn from(e: crate::shader::ShaderError) -> Self {
        GpuError(e.0)
    }
}

/// A wgpu device and its queue.
pub struct Gpu {
    /// The device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says it is (name, driver, backend).
    pub info: wgpu::AdapterInfo,
}

impl Gpu {
    /// The highest-performance adapter wgpu finds (a real GPU before a software one such as
    /// lavapipe), or an error saying what to install.
    pub fn new() -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
            backends: wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY),
            ..wgpu::InstanceDescriptor::new_without_display_handle()
        });
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            ..Default::default()
        }))
        .map_err(|e| {
            GpuError(format!(
                "no GPU adapter found ({e}): install a Vulkan driver (on Debian, mesa-vulkan-drivers gives \
                 lavapipe, a CPU one) and the Vulkan loader (libvulkan1)"
            ))
        })?;
        let info = adapter.get_info();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("tessera"),
            // Filtering f32 textures where the GPU can: hardware sampling of the exemplar.
            required_features: adapter.features() & wgpu::Features::FLOAT32_FILTERABLE,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| GpuError(format!("the GPU adapter {} refused a device: {e}", info.name)))?;
        Ok(Gpu { device, queue, info })
    }

    /// "name (backend, driver)".
    pub fn describe(&self) -> String {
        format!("{} ({:?}, {} {})", self.info.name, self.info.backend, self.info.driver, self.info.driver_info)
    }
}
