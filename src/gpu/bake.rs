//! The compute bake of a tiling-and-blending texture (`shaders/bake.wgsl`): the GPU twin of
//! [`crate::texture::bake_rect`], texel for texel.

use super::synthesis::{SynthesisGroup, layout_entry, shader_module, time_batches, uniform_entry, wait};
use super::{Gpu, GpuError};
use crate::image::Bitmap;
use crate::shader::BAKE_ENTRY_POINT;
use crate::texture::tiling_blending::params::HardwareSampling;
use crate::texture::{BakeFootprint, BakeParams, TilingBlending};
use wgpu::util::DeviceExt;

/// Workgroup size of the bake entry point (8 x 8).
const WORKGROUP: u32 = 8;

/// A tiling-and-blending texture uploaded to the GPU with the bake pipeline, ready to bake at
/// any resolution.
pub struct GpuBake<'g> {
    gpu: &'g Gpu,
    pipeline: wgpu::ComputePipeline,
    synthesis_group: wgpu::BindGroup,
    bake_layout: wgpu::BindGroupLayout,
}

impl<'g> GpuBake<'g> {
    /// Upload `texture` (its exemplar pyramid, F map, priority map and inverse histogram
    /// tables) and build the pipeline; an error names what the port lacks for this texture.
    pub fn new(gpu: &'g Gpu, texture: &TilingBlending) -> Result<Self, GpuError> {
        Self::with_sampling(gpu, texture, None)
    }

    /// [`GpuBake::new`], the exemplar read by the shader's f32 filters (`hardware` None: regime
    /// (a) of docs/gpu.md) or by the texture unit (regime (b)).
    pub fn with_sampling(
        gpu: &'g Gpu,
        texture: &TilingBlending,
        hardware: Option<HardwareSampling>,
    ) -> Result<Self, GpuError> {
        let device = &gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let synthesis = SynthesisGroup::new(gpu, texture, hardware)?;
        let module = shader_module(gpu);
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let compute = wgpu::ShaderStages::COMPUTE;
        let bake_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake"),
            entries: &[uniform_entry(0, compute), layout_entry(1, compute, storage)],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bake"),
            bind_group_layouts: &[Some(&synthesis.layout), Some(&bake_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("bake"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some(BAKE_ENTRY_POINT),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants: &synthesis.constants,
                zero_initialize_workgroup_memory: true,
            },
            cache: None,
        });
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError(format!("the GPU refused the tiling-and-blending pipeline: {e}")));
        }
        Ok(GpuBake { gpu, pipeline, synthesis_group: synthesis.group, bake_layout })
    }

    /// Rows per band of a bake `width` texels wide: as many as one storage buffer binding
    /// holds.
    fn band_rows(&self, width: u32, height: u32) -> u32 {
        let limits = self.gpu.device.limits();
        let bytes = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        (bytes / (width as u64 * 16)).clamp(1, height as u64) as u32
    }

    /// The bands of `rows` rows of a `width` x `height` bake: an output buffer of one band, and
    /// per band its first row, its row count and its bind group.
    fn bands(
        &self,
        width: u32,
        height: u32,
        footprint: BakeFootprint,
        rows: u32,
    ) -> (wgpu::Buffer, Vec<(u32, u32, wgpu::BindGroup)>) {
        let device = &self.gpu.device;
        let output = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bake output"),
            size: width as u64 * rows as u64 * 16,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let bands = (0..height)
            .step_by(rows as usize)
            .map(|first_row| {
                let params = BakeParams {
                    width,
                    height,
                    footprint: match footprint {
                        BakeFootprint::Texel => 0,
                        BakeFootprint::Point => 1,
                    },
                    first_row,
                };
                let params = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("bake params"),
                    contents: bytemuck::bytes_of(&params),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("bake"),
                    layout: &self.bake_layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: params.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 1, resource: output.as_entire_binding() },
                    ],
                });
                (first_row, rows.min(height - first_row), group)
            })
            .collect();
        (output, bands)
    }

    /// Record the dispatch of one band.
    fn dispatch(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        group: &wgpu::BindGroup,
        width: u32,
        rows: u32,
        times: usize,
    ) {
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.synthesis_group, &[]);
        pass.set_bind_group(1, group, &[]);
        for _ in 0..times {
            pass.dispatch_workgroups(width.div_ceil(WORKGROUP), rows.div_ceil(WORKGROUP), 1);
        }
    }

    /// The RGBA bake at `width` x `height` texel centres, row 0 at the top, as
    /// [`crate::texture::bake_rect`] lays it out.
    pub fn bake(&self, width: u32, height: u32, footprint: BakeFootprint) -> Result<Bitmap, GpuError> {
        self.bake_in_bands(width, height, footprint, self.band_rows(width, height))
    }

    /// [`GpuBake::bake`] in bands of `rows` rows.
    fn bake_in_bands(&self, width: u32, height: u32, footprint: BakeFootprint, rows: u32) -> Result<Bitmap, GpuError> {
        let device = &self.gpu.device;
        let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
        let (output, bands) = self.bands(width, height, footprint, rows);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("bake readback"),
            size: output.size(),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut image = Bitmap::new(width as usize, height as usize, 4);
        for (first_row, rows, group) in &bands {
            let mut encoder = device.create_command_encoder(&Default::default());
            self.dispatch(&mut encoder, group, width, *rows, 1);
            let bytes = width as u64 * *rows as u64 * 16;
            encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
            self.gpu.queue.submit([encoder.finish()]);
            readback.map_async(wgpu::MapMode::Read, ..bytes, |_| {});
            wait(self.gpu)?;
            {
                let view =
                    readback.get_mapped_range(..bytes).map_err(|e| GpuError(format!("reading the bake back: {e}")))?;
                let start = *first_row as usize * width as usize * 4;
                image.data[start..start + view.len() / 4].copy_from_slice(bytemuck::cast_slice(&view));
            }
            readback.unmap();
        }
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(GpuError(format!("the GPU bake failed: {e}")));
        }
        Ok(image)
    }

    /// Seconds per bake of `width` x `height` lookups: `batches` batches of `launches` bakes,
    /// each batch submitted at once and waited for (after one unmeasured batch).
    pub fn time(
        &self,
        width: u32,
        height: u32,
        footprint: BakeFootprint,
        launches: usize,
        batches: usize,
    ) -> Result<Vec<f64>, GpuError> {
        let (_output, bands) = self.bands(width, height, footprint, self.band_rows(width, height));
        time_batches(self.gpu, launches, batches, |encoder| {
            for (_, rows, group) in &bands {
                self.dispatch(encoder, group, width, *rows, launches);
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::texture::tiling_blending::{Blend, Synthesis, Tiling};
    use crate::texture::{Filter, ImageTexture, MipMap, Texture};
    use glam::Vec2;
    use std::sync::Arc;

    #[test]
    fn a_bake_in_bands_is_the_bake_in_one() {
        let gpu = Gpu::new().unwrap_or_else(|e| panic!("this test needs a Vulkan device: {e}"));
        let mut exemplar = Bitmap::new(32, 32, 4);
        for (i, v) in exemplar.data.iter_mut().enumerate() {
            *v = ((i * 7919) % 101) as f32 / 100.0;
        }
        let exemplar = Arc::new(Texture::Image(ImageTexture {
            mipmap: Arc::new(MipMap::new(exemplar)),
            filter: Filter::Trilinear,
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
        }));
        let synthesis = Synthesis {
            tiling: Tiling::Square,
            tile_size: 0.3,
            seed: 9,
            deformation: None,
            cuts: None,
            blend: Blend::Linear,
            inset: false,
        };
        let texture = TilingBlending::new(Arc::new(synthesis), exemplar).unwrap();
        let baker = GpuBake::new(&gpu, &texture).unwrap();
        let whole = baker.bake_in_bands(40, 30, BakeFootprint::Texel, 30).unwrap();
        // Bands of 7 rows, the last one short.
        assert_eq!(baker.bake_in_bands(40, 30, BakeFootprint::Texel, 7).unwrap(), whole);
        assert_eq!(whole, baker.bake(40, 30, BakeFootprint::Texel).unwrap());
    }
}
