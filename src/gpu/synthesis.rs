//! What every GPU pipeline of tiling and blending shares: the shader module, and a texture's
//! synthesis uploaded as `shaders/tiling_blending/params.wgsl`'s group 0 (the parameter block,
//! the exemplar's pyramid, the F map, the priority map, the inverse histogram tables, the
//! hardware sampler) and `cuts.wgsl`'s cut bands.

use super::{Gpu, GpuError};
use crate::image::Bitmap;
use crate::shader::wgsl_source;
use crate::texture::tiling_blending::params::{GpuCuts, GpuSynthesis, HardwareSampling};
use crate::texture::{MipMap, TilingBlending};
use wgpu::util::DeviceExt;

/// The stages that read the synthesis: the bake's compute shader and the view's fragment shader.
const STAGES: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE.union(wgpu::ShaderStages::FRAGMENT);

/// A layout entry visible to `visibility`.
pub(super) fn layout_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    ty: wgpu::BindingType,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None }
}

/// A uniform buffer's layout entry.
pub(super) fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    layout_entry(
        binding,
        visibility,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

/// The tiling-and-blending shader module (every file of [`crate::shader::SHADER_FILES`]).
pub(super) fn shader_module(gpu: &Gpu) -> wgpu::ShaderModule {
    let source = wgpu::ShaderModuleDescriptor {
        label: Some("tiling_blending"),
        source: wgpu::ShaderSource::Wgsl(wgsl_source().into()),
    };
    // wgpu bounds every loop with a hidden counter unless told otherwise; the counter keeps
    // the compiler from unrolling the loops over the k tiles, whose arrays then live in
    // local memory: the lookups ran 3 to 8 times slower on an H100 (docs/gpu.md). Bounds
    // checks and integer division checks stay.
    let mut checks = wgpu::ShaderRuntimeChecks::checked();
    checks.force_loop_bounding = false;
    // SAFETY: without the counter a loop that never ends would hang the GPU. Every loop of
    // the shaders ends: the loops over tiles, factors and support corners run to constants
    // (at most 4, 4 and 6: the factor count is checked against MAX_GPU_FACTORS before
    // upload), and the EWA loops over texel rows and columns are capped at MAX_EWA_SPAN
    // iterations (mipmap.wgsl), NaN footprints included.
    #[allow(unsafe_code)]
    unsafe {
        gpu.device.create_shader_module_trusted(source, checks)
    }
}

/// An f32 RGBA texture holding every level of `levels`.
fn upload_pyramid(gpu: &Gpu, label: &str, levels: &[&Bitmap]) -> wgpu::Texture {
    let mut data = Vec::new();
    for level in levels {
        for y in 0..level.height {
            for x in 0..level.width {
                data.extend_from_slice(bytemuck::bytes_of(&level.pixel(x, y).to_array()));
            }
        }
    }
    gpu.device.create_texture_with_data(
        &gpu.queue,
        &wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d {
                width: levels[0].width as u32,
                height: levels[0].height as u32,
                depth_or_array_layers: 1,
            },
            mip_level_count: levels.len() as u32,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        },
        wgpu::util::TextureDataOrder::LayerMajor,
        &data,
    )
}

/// A MIP pyramid as a texture; a 1 x 1 placeholder for an image the synthesis does not read.
fn upload_mipmap(gpu: &Gpu, label: &str, mipmap: Option<&MipMap>) -> wgpu::Texture {
    let placeholder = Bitmap::new(1, 1, 4);
    let levels: Vec<&Bitmap> = match mipmap {
        Some(m) => (0..m.level_count()).map(|l| m.level(l)).collect(),
        None => vec![&placeholder],
    };
    upload_pyramid(gpu, label, &levels)
}

/// A read-only storage buffer's layout entry.
fn storage_entry(binding: u32) -> wgpu::BindGroupLayoutEntry {
    layout_entry(
        binding,
        STAGES,
        wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
    )
}

/// The cut bands uploaded (`cuts.wgsl`'s bindings 6 to 9); one-element placeholders without.
struct CutResources {
    texels: wgpu::Texture,
    points: wgpu::Buffer,
    curves: wgpu::Buffer,
    anchors: wgpu::Buffer,
}

impl CutResources {
    fn new(gpu: &Gpu, cuts: Option<&GpuCuts>) -> Self {
        let empty = GpuCuts {
            res: 1,
            texels: vec![[u32::MAX, 0, u32::MAX, 0]],
            points: vec![Default::default()],
            curves: vec![Default::default()],
            anchors: vec![[0.0; 2]],
        };
        let cuts = cuts.unwrap_or(&empty);
        let buffer = |label, contents: &[u8]| {
            gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let texels = gpu.device.create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some("cut texels"),
                size: wgpu::Extent3d { width: cuts.res as u32, height: cuts.res as u32, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::Rgba32Uint,
                usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            bytemuck::cast_slice(&cuts.texels),
        );
        CutResources {
            texels,
            points: buffer("cut points", bytemuck::cast_slice(&cuts.points)),
            curves: buffer("cut curves", bytemuck::cast_slice(&cuts.curves)),
            anchors: buffer("cut anchors", bytemuck::cast_slice(&cuts.anchors)),
        }
    }
}

/// A texture's synthesis on the GPU: group 0 of every tiling-and-blending pipeline, and the
/// pipeline constants that specialise the shader to it.
pub(super) struct SynthesisGroup {
    /// The layout of `params.wgsl`'s group 0: the parameter block, four f32 textures (read
    /// with textureLoad, or sampled where the GPU filters f32 textures) and a sampler.
    pub layout: wgpu::BindGroupLayout,
    /// The bind group.
    pub group: wgpu::BindGroup,
    /// [`crate::texture::tiling_blending::params::SynthesisParams::pipeline_constants`].
    pub constants: Vec<(&'static str, f64)>,
}

impl SynthesisGroup {
    /// Upload `texture`, its exemplar read by the shader's filters or by the texture unit
    /// (`hardware`); an error names what the port or the GPU lacks for it.
    pub fn new(gpu: &Gpu, texture: &TilingBlending, hardware: Option<HardwareSampling>) -> Result<Self, GpuError> {
        let mut lookup: GpuSynthesis = texture.gpu_synthesis().map_err(GpuError)?;
        let device = &gpu.device;
        let filterable = device.features().contains(wgpu::Features::FLOAT32_FILTERABLE);
        if let Some(sampling) = hardware {
            if !filterable {
                return Err(GpuError(format!(
                    "{} cannot filter 32-bit float textures (wgpu's FLOAT32_FILTERABLE), which hardware sampling of \
                     the f32 exemplar needs",
                    gpu.info.name
                )));
            }
            if !(1..=16).contains(&sampling.anisotropy) {
                return Err(GpuError(format!("anisotropy {} is outside 1..=16", sampling.anisotropy)));
            }
            lookup.params.sample_exemplar_in_hardware(sampling.gradient_scale);
        }
        let texture_entry = |binding| {
            layout_entry(
                binding,
                STAGES,
                wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
            )
        };
        let sampler_type =
            if filterable { wgpu::SamplerBindingType::Filtering } else { wgpu::SamplerBindingType::NonFiltering };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("synthesis"),
            entries: &[
                uniform_entry(0, STAGES),
                texture_entry(1),
                texture_entry(2),
                texture_entry(3),
                texture_entry(4),
                layout_entry(5, STAGES, wgpu::BindingType::Sampler(sampler_type)),
                layout_entry(
                    6,
                    STAGES,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Uint,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                storage_entry(7),
                storage_entry(8),
                storage_entry(9),
            ],
        });
        // Trilinear with repeat wrapping, as tessera's filters; nearest where the GPU does not
        // filter f32 (the shader's filters then never sample).
        let linear = if filterable { wgpu::FilterMode::Linear } else { wgpu::FilterMode::Nearest };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("hardware sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: linear,
            min_filter: linear,
            mipmap_filter: if filterable { wgpu::MipmapFilterMode::Linear } else { wgpu::MipmapFilterMode::Nearest },
            anisotropy_clamp: hardware.map_or(1, |h| h.anisotropy),
            ..Default::default()
        });
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("synthesis params"),
            contents: bytemuck::bytes_of(&lookup.params),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let placeholder = Bitmap::new(1, 1, 4);
        let textures = [
            upload_mipmap(gpu, "exemplar", Some(lookup.exemplar)),
            upload_mipmap(gpu, "f map", lookup.f_map),
            upload_mipmap(gpu, "priority", lookup.priority),
            upload_pyramid(gpu, "inverse tables", &[lookup.inverse_tables.as_ref().unwrap_or(&placeholder)]),
        ];
        let views: Vec<wgpu::TextureView> = textures.iter().map(|t| t.create_view(&Default::default())).collect();
        let mut entries = vec![wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() }];
        for (i, view) in views.iter().enumerate() {
            entries.push(wgpu::BindGroupEntry {
                binding: i as u32 + 1,
                resource: wgpu::BindingResource::TextureView(view),
            });
        }
        entries.push(wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::Sampler(&sampler) });
        let cuts = CutResources::new(gpu, lookup.cuts.as_ref());
        let cut_texels = cuts.texels.create_view(&Default::default());
        entries.push(wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::TextureView(&cut_texels) });
        for (binding, buffer) in [(7, &cuts.points), (8, &cuts.curves), (9, &cuts.anchors)] {
            entries.push(wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() });
        }
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("synthesis"),
            layout: &layout,
            entries: &entries,
        });
        Ok(SynthesisGroup { layout, group, constants: lookup.params.pipeline_constants() })
    }
}

/// Seconds per unit of work: `batches` batches, each recorded by `record` (which records
/// `units` units of work) into one submission and waited for, after one unmeasured batch.
pub(super) fn time_batches(
    gpu: &Gpu,
    units: usize,
    batches: usize,
    record: impl Fn(&mut wgpu::CommandEncoder),
) -> Result<Vec<f64>, GpuError> {
    let mut seconds = Vec::new();
    for batch in 0..=batches {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        record(&mut encoder);
        let start = std::time::Instant::now();
        gpu.queue.submit([encoder.finish()]);
        wait(gpu)?;
        if batch > 0 {
            seconds.push(start.elapsed().as_secs_f64() / units as f64);
        }
    }
    Ok(seconds)
}

/// Wait for the GPU to finish what was submitted.
pub(super) fn wait(gpu: &Gpu) -> Result<(), GpuError> {
    gpu.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map(|_| ())
        .map_err(|e| GpuError(format!("waiting for the GPU: {e}")))
}
