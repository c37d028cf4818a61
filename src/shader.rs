//! The WGSL port of deformed tiling and blending (`shaders/`): its source, assembled from the
//! files that mirror `src/texture/tiling_blending/` one for one, validated by naga, and
//! translated by naga's back ends for engines that do not take WGSL.
//!
//! WGSL has no include: [`wgsl_source`] concatenates the files in dependency order, each
//! preceded by a comment naming it, so that naga's error positions can be traced back.

use std::fmt;

/// The shader files, in the order they are concatenated, and their text.
pub const SHADER_FILES: &[(&str, &str)] = &[
    ("tiling_blending/params.wgsl", include_str!("../shaders/tiling_blending/params.wgsl")),
    ("tiling_blending/shift.wgsl", include_str!("../shaders/tiling_blending/shift.wgsl")),
    ("tiling_blending/tiling.wgsl", include_str!("../shaders/tiling_blending/tiling.wgsl")),
    ("tiling_blending/mipmap.wgsl", include_str!("../shaders/tiling_blending/mipmap.wgsl")),
    ("tiling_blending/deformation.wgsl", include_str!("../shaders/tiling_blending/deformation.wgsl")),
    ("tiling_blending/cuts.wgsl", include_str!("../shaders/tiling_blending/cuts.wgsl")),
    ("tiling_blending/operators.wgsl", include_str!("../shaders/tiling_blending/operators.wgsl")),
    ("tiling_blending/synthesis.wgsl", include_str!("../shaders/tiling_blending/synthesis.wgsl")),
    ("bake.wgsl", include_str!("../shaders/bake.wgsl")),
    ("view.wgsl", include_str!("../shaders/view.wgsl")),
];

/// The compute entry point that bakes a texture over the UV square (`shaders/bake.wgsl`).
pub const BAKE_ENTRY_POINT: &str = "bake";

/// The vertex and fragment entry points of the rasterised view (`shaders/view.wgsl`).
pub const VIEW_ENTRY_POINTS: (&str, &str) = ("view_vertex", "view_fragment");

/// The whole WGSL module: the files of [`SHADER_FILES`] concatenated.
pub fn wgsl_source() -> String {
    SHADER_FILES.iter().map(|(name, text)| format!("// ---- shaders/{name}\n{text}\n")).collect()
}

/// A shading language naga can write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShaderLanguage {
    /// WGSL, as naga writes it back (one file, no comments).
    Wgsl,
    /// GLSL 4.50 core for Vulkan-style bindings (binding = 16 group + binding).
    Glsl,
    /// HLSL shader model 5.1.
    Hlsl,
    /// Metal Shading Language 2.0.
    Msl,
}

/// Which shader to export.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShaderEntry {
    /// The compute bake of the UV square (`bake.wgsl`).
    Bake,
    /// The rasterised view (`view.wgsl`): its fragment shader, the lookup an engine's material
    /// makes (GLSL holds one stage per file); HLSL, MSL and WGSL hold its vertex shader too.
    View,
}

impl ShaderEntry {
    /// The entry point GLSL gets, and its stage.
    fn glsl_stage(self) -> (naga::ShaderStage, &'static str) {
        match self {
            ShaderEntry::Bake => (naga::ShaderStage::Compute, BAKE_ENTRY_POINT),
            ShaderEntry::View => (naga::ShaderStage::Fragment, VIEW_ENTRY_POINTS.1),
        }
    }

    /// The entry points an export keeps.
    fn entry_points(self) -> &'static [&'static str] {
        match self {
            ShaderEntry::Bake => &[BAKE_ENTRY_POINT],
            ShaderEntry::View => &[VIEW_ENTRY_POINTS.0, VIEW_ENTRY_POINTS.1],
        }
    }
}

/// Why the shaders could not be parsed, validated or translated.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct ShaderError(pub String);

/// The parsed and validated module.
pub fn module() -> Result<(naga::Module, naga::valid::ModuleInfo), ShaderError> {
    let source = wgsl_source();
    let module = naga::front::wgsl::parse_str(&source)
        .map_err(|e| ShaderError(format!("WGSL parse error:\n{}", e.emit_to_string(&source))))?;
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .map_err(|e| ShaderError(format!("WGSL validation error:\n{}", e.emit_to_string(&source))))?;
    Ok((module, info))
}

/// The shader of `entry` in `language`, general (the specialising pipeline constants of
/// `params.wgsl` at their defaults: the uniform block decides), with the functions it calls.
pub fn export(language: ShaderLanguage, entry: ShaderEntry) -> Result<String, ShaderError> {
    let (mut module, _) = module()?;
    // Keep only the entry points exported; naga's back ends then write what they reach.
    module.entry_points.retain(|e| entry.entry_points().contains(&e.name.as_str()));
    let info = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
        .validate(&module)
        .map_err(|e| ShaderError(format!("WGSL validation error: {e}")))?;
    let (module, info) = naga::back::pipeline_constants::process_overrides(
        &module,
        &info,
        None,
        &naga::back::PipelineConstants::default(),
    )
    .map_err(|e| ShaderError(format!("resolving the pipeline constants: {e}")))?;
    let (module, info) = (module.into_owned(), info.into_owned());
    let failed = |what: &str, e: &dyn fmt::Display| ShaderError(format!("{what} back end: {e}"));
    match language {
        ShaderLanguage::Wgsl => naga::back::wgsl::write_string(&module, &info, naga::back::wgsl::WriterFlags::empty())
            .map_err(|e| failed("WGSL", &e)),
        ShaderLanguage::Glsl => {
            let binding_map = module
                .global_variables
                .iter()
                .filter_map(|(_, g)| g.binding)
                .map(|b| {
                    let slot = (16 * b.group + b.binding) as u8;
                    (b, slot)
                })
                .collect();
            let options = naga::back::glsl::Options {
                version: naga::back::glsl::Version::Desktop(450),
                writer_flags: naga::back::glsl::WriterFlags::empty(),
                binding_map,
                zero_initialize_workgroup_memory: true,
            };
            let (shader_stage, entry_point) = entry.glsl_stage();
            let pipeline =
                naga::back::glsl::PipelineOptions { shader_stage, entry_point: entry_point.into(), multiview: None };
            let mut out = String::new();
            let mut writer = naga::back::glsl::Writer::new(
                &mut out,
                &module,
                &info,
                &options,
                &pipeline,
                naga::proc::BoundsCheckPolicies::default(),
            )
            .map_err(|e| failed("GLSL", &e))?;
            writer.write().map_err(|e| failed("GLSL", &e))?;
            Ok(out)
        }
        ShaderLanguage::Hlsl => {
            let options = naga::back::hlsl::Options::default();
            let pipeline = naga::back::hlsl::PipelineOptions { entry_point: None };
            let mut out = String::new();
            naga::back::hlsl::Writer::new(&mut out, &options, &pipeline)
                .write(&module, &info, None)
                .map_err(|e| failed("HLSL", &e))?;
            Ok(out)
        }
        ShaderLanguage::Msl => {
            let options = naga::back::msl::Options { lang_version: (2, 0), ..Default::default() };
            let pipeline = naga::back::msl::PipelineOptions::default();
            naga::back::msl::write_string(&module, &info, &options, &pipeline)
                .map(|(text, _)| text)
                .map_err(|e| failed("MSL", &e))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::primary::{Derivatives, ViewParams, ViewTriangle};
    use crate::texture::tiling_blending::params::{
        CutCurveParams, CutPointParams, FactorParams, ImageParams, SynthesisParams,
    };
    use std::mem::{offset_of, size_of};

    #[test]
    fn the_shaders_parse_and_validate() {
        if let Err(e) = module() {
            panic!("{e}");
        }
    }

    /// A WGSL struct's size and its members' names and offsets, as naga lays it out.
    fn wgsl_layout(module: &naga::Module, name: &str) -> (u32, Vec<(String, u32)>) {
        let ty = module.types.iter().find(|(_, t)| t.name.as_deref() == Some(name));
        let Some((_, naga::Type { inner: naga::TypeInner::Struct { members, span }, .. })) = ty else {
            panic!("no struct {name} in the shaders");
        };
        (*span, members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset)).collect())
    }

    macro_rules! rust_layout {
        ($ty:ty { $($field:ident),* $(,)? }) => {
            (size_of::<$ty>() as u32, vec![$((stringify!($field).to_string(), offset_of!($ty, $field) as u32)),*])
        };
    }

    #[test]
    fn the_parameter_block_has_the_same_layout_on_both_sides() {
        let (module, _) = module().unwrap();
        let expected = [
            ("ImageParams", rust_layout!(ImageParams { filtering, levels, scale, offset, gradient_scale, padding })),
            ("FactorParams", rust_layout!(FactorParams { kind, padding, values })),
            (
                "SynthesisParams",
                rust_layout!(SynthesisParams {
                    tiling,
                    seed,
                    blend,
                    inset,
                    tile_size,
                    factor_count,
                    mix_max,
                    exemplar_mean,
                    exemplar,
                    priority,
                    factors,
                    cuts,
                    padding,
                }),
            ),
            ("BakeParams", rust_layout!(crate::texture::BakeParams { width, height, footprint, first_row })),
            ("CutPointParams", rust_layout!(CutPointParams { uv0, uv1, g, s, padding })),
            (
                "CutCurveParams",
                rust_layout!(CutCurveParams { first_point, point_count, first_anchor, anchor_count, spacing, padding }),
            ),
            (
                "ViewParams",
                rust_layout!(ViewParams { clip_from_world, eye, corner_direction, pixel_step_x, pixel_step_y }),
            ),
            (
                "ViewTriangle",
                rust_layout!(ViewTriangle { p0, p1, p2, ng, dpdu, dpdv, uv0, uv1, uv2, surface, padding }),
            ),
        ];
        for (name, rust) in expected {
            assert_eq!(wgsl_layout(&module, name), rust, "{name}: WGSL (size, members) against Rust");
        }
    }

    #[test]
    fn the_constants_match() {
        use crate::texture::tiling_blending::params::*;
        let (module, _) = module().unwrap();
        let constant = |name: &str| -> u32 {
            let (_, c) = module.constants.iter().find(|(_, c)| c.name.as_deref() == Some(name)).unwrap();
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v,
                naga::Expression::Literal(naga::Literal::F32(v)) => v.to_bits(),
                naga::Expression::Literal(naga::Literal::I32(v)) => v as u32,
                ref other => panic!("{name}: {other:?}"),
            }
        };
        for (name, value) in [
            ("FILTER_NONE", FILTER_NONE),
            ("FILTER_TRILINEAR", FILTER_TRILINEAR),
            ("FILTER_EWA", FILTER_EWA),
            ("FILTER_HARDWARE", FILTER_HARDWARE),
            ("TILING_HEXAGONAL", TILING_HEXAGONAL),
            ("TILING_SQUARE", TILING_SQUARE),
            ("BLEND_LINEAR", BLEND_LINEAR),
            ("BLEND_VARIANCE_PRESERVING", BLEND_VARIANCE_PRESERVING),
            ("BLEND_HISTOGRAM_PRESERVING", BLEND_HISTOGRAM_PRESERVING),
            ("BLEND_MIX_MAX", BLEND_MIX_MAX),
            ("FACTOR_CONSTANT", FACTOR_CONSTANT),
            ("FACTOR_ROTATION", FACTOR_ROTATION),
            ("FACTOR_SCALE", FACTOR_SCALE),
            ("FACTOR_SHEAR", FACTOR_SHEAR),
            ("FACTOR_MAP", FACTOR_MAP),
            ("MAX_GPU_FACTORS", MAX_GPU_FACTORS as u32),
            ("EWA_LUT_SIZE", crate::texture::EWA_LUT_SIZE as u32),
            ("MAX_EWA_SPAN", crate::texture::MAX_EWA_SPAN as u32),
            ("MAX_ANISOTROPY", crate::texture::MAX_ANISOTROPY.to_bits()),
            ("MAX_DEFORMATION", crate::texture::tiling_blending::MAX_DEFORMATION.to_bits()),
            ("SURFACE_UNMIRRORED", crate::integrator::primary::SURFACE_UNMIRRORED),
            ("SURFACE_MIRRORED", crate::integrator::primary::SURFACE_MIRRORED),
            ("CUT_SALT", crate::texture::tiling_blending::CUT_SALT),
            ("CUT_SEARCH", crate::texture::tiling_blending::CUT_SEARCH as u32),
            ("BANDS_PER_POINT", crate::texture::tiling_blending::BANDS_PER_POINT as u32),
            ("DERIVATIVES_DPDX", Derivatives::Dpdx.code()),
            ("DERIVATIVES_COARSE", Derivatives::Coarse.code()),
            ("DERIVATIVES_FINE", Derivatives::Fine.code()),
            ("DERIVATIVES_RAY", Derivatives::Ray.code()),
        ] {
            assert_eq!(constant(name), value, "{name}");
        }
    }

    #[test]
    fn every_language_exports() {
        for language in [ShaderLanguage::Wgsl, ShaderLanguage::Glsl, ShaderLanguage::Hlsl, ShaderLanguage::Msl] {
            for entry in [ShaderEntry::Bake, ShaderEntry::View] {
                let text = export(language, entry).unwrap_or_else(|e| panic!("{language:?} {entry:?}: {e}"));
                assert!(text.len() > 1000, "{language:?} {entry:?}: {} bytes", text.len());
                // Each export holds its own entry points and not the other's.
                let (has, lacks) = match entry {
                    ShaderEntry::Bake => (BAKE_ENTRY_POINT, VIEW_ENTRY_POINTS.1),
                    ShaderEntry::View => (VIEW_ENTRY_POINTS.1, BAKE_ENTRY_POINT),
                };
                if language != ShaderLanguage::Glsl {
                    assert!(text.contains(has), "{language:?} {entry:?} lacks {has}");
                }
                assert!(!text.contains(&format!("{lacks}(")), "{language:?} {entry:?} holds {lacks}");
            }
        }
    }
}
