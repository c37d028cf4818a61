//! The rasterised view of `tessera gpu-view` (`shaders/view.wgsl`): a mesh scene drawn with a
//! tiling-and-blending texture on every surface, the GPU twin of
//! [`crate::integrator::primary::primary_view`], pixel for pixel.

use super::synthesis::{SynthesisGroup, layout_entry, shader_module, time_batches, uniform_entry, wait};
use super::{Gpu, GpuError};
use crate::camera::Camera;
use crate::integrator::primary::{Derivatives, PrimaryView, ViewParams, ViewVertex, near_plane, view_geometry};
use crate::scene::Scene;
use crate::shader::VIEW_ENTRY_POINTS;
use crate::texture::TilingBlending;
use crate::texture::tiling_blending::params::HardwareSampling;
use wgpu::util::DeviceExt;

/// The colour targets: the value, the footprint (both RGBA f32) and the triangle plus one.
const TARGETS: [wgpu::TextureFormat; 3] =
    [wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::R32Uint];

/// Depth: reversed (1 at the near plane, 0 at infinity), cleared to 0, nearer is greater.
const DEPTH: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// A scene and a tiling-and-blending texture uploaded to the GPU, ready to draw through one
/// camera.
pub struct GpuView<'g> {
    gpu: &'g Gpu,
    synthesis: SynthesisGroup,
    module: wgpu::ShaderModule,
    pipeline_layout: wgpu::PipelineLayout,
    view_group: wgpu::BindGroup,
    vertices: wgpu::Buffer,
    vertex_count: u32,
    width: u32,
    height: u32,
    targets: Vec<wgpu::Texture>,
    depth: wgpu::Texture,
}

/// A render target of the view's size.
fn target(gpu: &Gpu, label: &str, format: wgpu::TextureFormat, width: u32, height: u32) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

impl<'g> GpuView<'g> {
    /// Upload `scene`'s triangles and `texture`, for views through `camera` (its resolution is
    /// the view's), the exemplar read by the shader's f32 filters or by the texture unit
    /// (`hardware`); an error names what the GPU or the port lacks.
    pub fn new(
        gpu: &'g Gpu,
        scene: &Scene,
        camera: &Camera,
        texture: &TilingBlending,
        hardware: Option<HardwareSampling>,
    ) -> Result<Self, GpuError> {
        camera.require_pinhole("the GPU view").map_err(|e| GpuError(e.to_string()))?;
        let device = &gpu.device;
        let (width, height) = camera.resolution();
        let limits = device.limits();
        if width > limits.max_texture_dimension_2d || height > limits.max_texture_dimension_2d {
            return Err(GpuError(format!(
                "a {width} x {height} view exceeds the GPU's largest render target side, {}",
                limits.max_texture_dimension_2d
            )));
        }
        if !scene.geometry.spheres.is_empty() {
            return Err(GpuError(format!(
                "{} has exact spheres, which the GPU view does not rasterise: use uv_sphere meshes",
                scene.path.display()
            )));
        }
        let (vertices, triangles) = view_geometry(&scene.geometry);
        if triangles.is_empty() {
            return Err(GpuError(format!("{} has no triangles to draw", scene.path.display())));
        }
        let bytes = (triangles.len() * size_of_val(&triangles[0])) as u64;
        if bytes > limits.max_storage_buffer_binding_size.min(limits.max_buffer_size) {
            return Err(GpuError(format!(
                "{} triangles take {bytes} bytes, more than the GPU's largest storage buffer ({} bytes)",
                triangles.len(),
                limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
            )));
        }
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let synthesis = SynthesisGroup::new(gpu, texture, hardware)?;
        let module = shader_module(gpu);
        let both = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let view_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("view"),
            entries: &[uniform_entry(0, both), layout_entry(1, wgpu::ShaderStages::FRAGMENT, storage)],
        });
        // Group 1 is the bake's; the view's is group 2.
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("view"),
            bind_group_layouts: &[Some(&synthesis.layout), None, Some(&view_layout)],
            immediate_size: 0,
        });
        let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("view params"),
            contents: bytemuck::bytes_of(&ViewParams::new(camera, near_plane(scene))),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let triangle_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("view triangles"),
            contents: bytemuck::cast_slice(&triangles),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let view_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("view"),
            layout: &view_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: triangle_buffer.as_entire_binding() },
            ],
        });
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("view vertices"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let targets = ["value", "footprint", "triangle"]
            .iter()
            .zip(TARGETS)
            .map(|(label, format)| target(gpu, label, format, width, height))
            .collect();
        let depth = target(gpu, "depth", DEPTH, width, height);
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError(format!("the GPU refused the view's resources: {e}")));
        }
        Ok(GpuView {
            gpu,
            synthesis,
            module,
            pipeline_layout,
            view_group,
            vertices: vertex_buffer,
            vertex_count: vertices.len() as u32,
            width,
            height,
            targets,
            depth,
        })
    }

    /// The render pipeline whose fragment shader takes its footprint from `derivatives`.
    fn pipeline(&self, derivatives: Derivatives) -> Result<wgpu::RenderPipeline, GpuError> {
        let device = &self.gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut constants = self.synthesis.constants.clone();
        constants.push(("DERIVATIVES", derivatives.code() as f64));
        let options =
            |constants| wgpu::PipelineCompilationOptions { constants, zero_initialize_workgroup_memory: true };
        let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x2, 2 => Uint32];
        let targets: Vec<Option<wgpu::ColorTargetState>> = TARGETS.iter().map(|&format| Some(format.into())).collect();
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("view"),
            layout: Some(&self.pipeline_layout),
            vertex: wgpu::VertexState {
                module: &self.module,
                entry_point: Some(VIEW_ENTRY_POINTS.0),
                compilation_options: options(&[]),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: size_of::<ViewVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &attributes,
                })],
            },
            // Both sides of every triangle, as the rays see them.
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &self.module,
                entry_point: Some(VIEW_ENTRY_POINTS.1),
                compilation_options: options(&constants),
                targets: &targets,
            }),
            multiview_mask: None,
            cache: None,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError(format!("the GPU refused the view's pipeline: {e}")));
        }
        Ok(pipeline)
    }

    /// Record one frame: clear, draw every triangle.
    fn draw(&self, encoder: &mut wgpu::CommandEncoder, pipeline: &wgpu::RenderPipeline) {
        let views: Vec<wgpu::TextureView> = self.targets.iter().map(|t| t.create_view(&Default::default())).collect();
        let attachments: Vec<Option<wgpu::RenderPassColorAttachment>> = views
            .iter()
            .map(|view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            })
            .collect();
        let depth = self.depth.create_view(&Default::default());
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("view"),
            color_attachments: &attachments,
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.synthesis.group, &[]);
        pass.set_bind_group(2, &self.view_group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.draw(0..self.vertex_count, 0..1);
    }

    /// The view with the footprint from `derivatives`.
    pub fn render(&self, derivatives: Derivatives) -> Result<PrimaryView, GpuError> {
        let device = &self.gpu.device;
        let pipeline = self.pipeline(derivatives)?;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let (width, height) = (self.width as usize, self.height as usize);
        // Rows of a copy are padded to 256 bytes.
        let row_bytes =
            |pixel_bytes: usize| (width * pixel_bytes).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as usize);
        let mut encoder = device.create_command_encoder(&Default::default());
        self.draw(&mut encoder, &pipeline);
        let readbacks: Vec<(wgpu::Buffer, usize)> = self
            .targets
            .iter()
            .zip(TARGETS)
            .map(|(texture, format)| {
                let pixel_bytes = format.block_copy_size(None).expect("colour formats have a copy size") as usize;
                let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("view readback"),
                    size: (row_bytes(pixel_bytes) * height) as u64,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                encoder.copy_texture_to_buffer(
                    texture.as_image_copy(),
                    wgpu::TexelCopyBufferInfo {
                        buffer: &buffer,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(row_bytes(pixel_bytes) as u32),
                            rows_per_image: None,
                        },
                    },
                    wgpu::Extent3d { width: self.width, height: self.height, depth_or_array_layers: 1 },
                );
                (buffer, pixel_bytes)
            })
            .collect();
        self.gpu.queue.submit([encoder.finish()]);
        for (buffer, _) in &readbacks {
            buffer.map_async(wgpu::MapMode::Read, .., |_| {});
        }
        wait(self.gpu)?;
        let mut view = PrimaryView::new(width, height);
        for (k, (buffer, pixel_bytes)) in readbacks.iter().enumerate() {
            let mapped = buffer.get_mapped_range(..).map_err(|e| GpuError(format!("reading the view back: {e}")))?;
            for y in 0..height {
                let row = &mapped[y * row_bytes(*pixel_bytes)..][..width * pixel_bytes];
                match k {
                    0 => view.value.data[y * width * 4..][..width * 4].copy_from_slice(bytemuck::cast_slice(row)),
                    1 => view.footprint.data[y * width * 4..][..width * 4].copy_from_slice(bytemuck::cast_slice(row)),
                    _ => view.triangle[y * width..][..width].copy_from_slice(bytemuck::cast_slice(row)),
                }
            }
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError(format!("the GPU view failed: {e}")));
        }
        Ok(view)
    }

    /// Seconds per frame with the footprint from `derivatives`: `batches` batches of `frames`
    /// frames, each batch submitted at once and waited for (after one unmeasured batch).
    pub fn time(&self, derivatives: Derivatives, frames: usize, batches: usize) -> Result<Vec<f64>, GpuError> {
        let pipeline = self.pipeline(derivatives)?;
        time_batches(self.gpu, frames, batches, |encoder| {
            for _ in 0..frames {
                self.draw(encoder, &pipeline);
            }
        })
    }
}
