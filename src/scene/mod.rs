//! Scenes: the file format ([`desc`]), loading ([`load`]), and the loaded scene that the
//! integrator queries.

pub mod desc;
mod gltf;
mod lights;
mod load;
mod mitsuba;
mod mitsuba_import;
mod set;

pub use load::{SceneOverrides, load_scene, load_scene_str, load_texture};
pub use mitsuba::{MitsubaExport, export_mitsuba};
pub use mitsuba_import::{MitsubaImport, import_mitsuba};

/// One mesh file's surface, by extension: OBJ, PLY or Mitsuba's serialized (its first mesh; no
/// tangents), or glTF 2.0 (.gltf, .glb: every
/// triangle primitive in world space, with per-vertex tangents where every primitive has
/// TANGENT). For `tessera deform`, which needs the surface and its UVs, not a scene; checked as
/// [`TriangleMesh::check`] does (degenerate triangles are kept: `deform` counts them).
pub fn load_surface(path: &std::path::Path) -> crate::Result<(TriangleMesh, Option<Vec<Vec3>>)> {
    let extension = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let (mesh, tangents) = match extension.as_deref() {
        Some("gltf" | "glb") => gltf::import_surface(path)?,
        Some("obj") => (crate::geometry::obj::load_obj(path)?, None),
        Some("ply") => (crate::geometry::ply::load_ply(path)?, None),
        Some("serialized") => (crate::geometry::serialized::load_serialized(path, 0)?, None),
        _ => {
            return Err(crate::Error::mesh(
                path,
                "expected a mesh file ending in .obj, .ply, .serialized, .gltf or .glb",
            ));
        }
    };
    mesh.check().map_err(|msg| crate::Error::mesh(path, msg))?;
    Ok((mesh, tangents))
}

use crate::accel::{Accel, Hit};
use crate::camera::Camera;
use crate::geometry::{Bounds, DEFAULT_UVS, Ray, Sphere, SurfaceInteraction, TriangleMesh, TriangleVertices};
use crate::light::Lights;
use crate::material::Material;
use crate::texture::Texture;
use glam::{Vec2, Vec3};
use std::path::PathBuf;

/// Image and integrator settings (the scene's `[render]` table after command-line overrides).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Longest path in segments (Mitsuba's count); None for unlimited.
    pub max_depth: Option<u32>,
    /// Depth from which Russian roulette applies.
    pub rr_depth: u32,
    /// Sampler seed.
    pub seed: u64,
    /// How samples are spread over and around each pixel.
    pub pixel_filter: crate::image::PixelFilter,
}

/// A shape as the renderer sees it after loading.
#[derive(Clone, Debug)]
pub struct Shape {
    /// Name for messages (`shapes[2] (sphere.obj)`).
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Index into the area lights, if the shape emits.
    pub light: Option<u32>,
    /// First vertex in [`Geometry`]'s arrays (for a sphere, where the next mesh's will be).
    pub first_vertex: u32,
    /// Index into [`Geometry::spheres`] when the shape is an exact sphere (it has no vertices).
    pub sphere: Option<u32>,
    /// Whether the mesh had normals and texture coordinates.
    pub has_normals: bool,
    /// See `has_normals`.
    pub has_uvs: bool,
}

/// All triangles of a scene in world space, in one set of arrays, and its exact spheres.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals (zero for shapes without normals).
    pub normals: Vec<Vec3>,
    /// Vertex texture coordinates (zero for shapes without them).
    pub uvs: Vec<Vec2>,
    /// Triangles as indices into the vertex arrays.
    pub triangles: Vec<[u32; 3]>,
    /// Shape of each triangle.
    pub triangle_shape: Vec<u32>,
    /// Exact spheres (primitives after the triangles: [`crate::accel::Hit::primitive`]).
    pub spheres: Vec<Sphere>,
    /// Shape of each sphere.
    pub sphere_shape: Vec<u32>,
    /// Shapes.
    pub shapes: Vec<Shape>,
}

impl Geometry {
    /// Append a mesh as a new shape.
    pub fn add(&mut self, mesh: TriangleMesh, name: String, material: u32, light: Option<u32>) {
        let first = self.positions.len() as u32;
        let n = mesh.positions.len();
        let shape = self.shapes.len() as u32;
        self.shapes.push(Shape {
            name,
            material,
            light,
            first_vertex: first,
            sphere: None,
            has_normals: mesh.normals.is_some(),
            has_uvs: mesh.uvs.is_some(),
        });
        self.positions.extend(&mesh.positions);
        self.normals.extend(mesh.normals.unwrap_or_else(|| vec![Vec3::ZERO; n]));
        self.uvs.extend(mesh.uvs.unwrap_or_else(|| vec![Vec2::ZERO; n]));
        self.triangles.extend(mesh.indices.iter().map(|t| t.map(|i| i + first)));
        self.triangle_shape.extend(std::iter::repeat_n(shape, mesh.indices.len()));
    }

    /// Append an exact sphere as a new shape.
    pub fn add_sphere(&mut self, sphere: Sphere, name: String, material: u32, light: Option<u32>) {
        let shape = self.shapes.len() as u32;
        self.shapes.push(Shape {
            name,
            material,
            light,
            first_vertex: self.positions.len() as u32,
            sphere: Some(self.spheres.len() as u32),
            has_normals: true,
            has_uvs: true,
        });
        self.spheres.push(sphere);
        self.sphere_shape.push(shape);
    }

    /// Vertex positions of triangle `i`.
    #[inline]
    pub fn triangle_positions(&self, i: usize) -> [Vec3; 3] {
        self.triangles[i].map(|v| self.positions[v as usize])
    }

    /// Vertex positions of every triangle, in order: what the accelerator is built over.
    pub fn all_triangle_positions(&self) -> Vec<[Vec3; 3]> {
        (0..self.triangles.len()).map(|t| self.triangle_positions(t)).collect()
    }

    /// Whether each triangle emits (belongs to a shape with an area light), in order: what the
    /// accelerator needs to know of them ([`crate::accel::Accel::build`]).
    pub fn emitting_triangles(&self) -> Vec<bool> {
        self.triangle_shape.iter().map(|&shape| self.shapes[shape as usize].light.is_some()).collect()
    }

    /// Corner `corner` (0, 1 or 2) of triangle `i`: its position, its shading normal (zero where
    /// the mesh has none) and its texture coordinates ([`DEFAULT_UVS`] where the mesh has none):
    /// what [`Geometry::triangle_vertices`] gives at that corner, read without building the
    /// triangle's arrays (lanes gather corner by corner, and a copy of the arrays stalls on
    /// their stores).
    #[inline(always)]
    pub fn triangle_corner(&self, i: usize, corner: usize) -> (Vec3, Vec3, Vec2) {
        let v = self.triangles[i][corner] as usize;
        let shape = &self.shapes[self.triangle_shape[i] as usize];
        // Meshes without normals or uvs store zeros for them (`Geometry::add`).
        let uv = if shape.has_uvs { self.uvs[v] } else { DEFAULT_UVS[corner] };
        (self.positions[v], self.normals[v], uv)
    }

    /// All vertex data of triangle `i`.
    #[inline(always)]
    pub fn triangle_vertices(&self, i: usize) -> TriangleVertices {
        let idx = self.triangles[i];
        let shape = &self.shapes[self.triangle_shape[i] as usize];
        TriangleVertices {
            p: idx.map(|v| self.positions[v as usize]),
            n: shape.has_normals.then(|| idx.map(|v| self.normals[v as usize])),
            uv: shape.has_uvs.then(|| idx.map(|v| self.uvs[v as usize])),
        }
    }

    /// Bounding box of all vertices and spheres.
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for p in &self.positions {
            b.include(*p);
        }
        self.spheres.iter().fold(b, |b, s| b.union(s.bounds()))
    }
}

/// A loaded scene, ready to render.
pub struct Scene {
    /// The file it came from.
    pub path: PathBuf,
    /// Image and integrator settings.
    pub settings: RenderSettings,
    /// The camera.
    pub camera: Camera,
    /// Triangles and shapes.
    pub geometry: Geometry,
    /// Ray intersection over `geometry`.
    pub accel: Accel,
    /// Materials; shapes index them.
    pub materials: Vec<Material>,
    /// Textures; materials index them.
    pub textures: Vec<Texture>,
    /// What the scene calls each texture, by index (`textures.NAME`, or a glTF file's image),
    /// for messages.
    pub texture_names: Vec<String>,
    /// Lights.
    pub lights: Lights,
    /// Problems found while loading that did not stop it (degenerate triangles dropped, glTF
    /// features ignored).
    pub warnings: Vec<String>,
}

impl Scene {
    /// The closest surface along `ray`.
    pub fn intersect(&self, ray: &Ray) -> Option<SurfaceInteraction> {
        Some(self.interaction(ray, &self.accel.intersect(ray)?))
    }

    /// The surface that `ray` meets at `hit` (an answer of [`Scene::accel`] for `ray`).
    pub fn interaction(&self, ray: &Ray, hit: &Hit) -> SurfaceInteraction {
        let g = &self.geometry;
        match (hit.primitive as usize).checked_sub(g.triangles.len()) {
            Some(sphere) => g.spheres[sphere].interaction(ray, hit.t, hit.primitive),
            None => {
                let tri = g.triangle_vertices(hit.primitive as usize);
                SurfaceInteraction::from_triangle(&tri, hit.b1, hit.b2, hit.t, ray, hit.primitive)
            }
        }
    }

    /// The shape a primitive (a triangle or a sphere: [`Hit::primitive`]) belongs to.
    #[inline]
    pub fn shape_of(&self, primitive: u32) -> &Shape {
        let g = &self.geometry;
        let shape = match (primitive as usize).checked_sub(g.triangles.len()) {
            Some(sphere) => g.sphere_shape[sphere],
            None => g.triangle_shape[primitive as usize],
        };
        &g.shapes[shape as usize]
    }

    /// Approximate memory held by geometry, acceleration structure and textures, in bytes.
    pub fn memory_bytes(&self) -> usize {
        let g = &self.geometry;
        let geometry = g.positions.len() * (12 + 12 + 8) + g.triangles.len() * (12 + 4);
        geometry + self.accel.memory_bytes() + self.textures.iter().map(Texture::memory_bytes).sum::<usize>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_corner_is_what_its_vertex_arrays_give_there() {
        let triangle = |k: f32| TriangleMesh {
            positions: vec![Vec3::new(k, 0.0, 1.0), Vec3::new(k + 1.0, 0.5, 0.0), Vec3::new(k, 2.0, -1.0)],
            normals: None,
            uvs: None,
            indices: vec![[0, 1, 2], [2, 1, 0]],
        };
        let mut geometry = Geometry::default();
        // With neither normals nor uvs, with both, with uvs only: corners read from each.
        geometry.add(triangle(0.0), "bare".into(), 0, None);
        let normals = Some(vec![Vec3::X, Vec3::Y, Vec3::Z]);
        let uvs = Some(vec![Vec2::new(0.1, 0.2), Vec2::new(0.3, 0.4), Vec2::new(0.5, 0.6)]);
        geometry.add(TriangleMesh { normals, uvs: uvs.clone(), ..triangle(3.0) }, "full".into(), 0, None);
        geometry.add(TriangleMesh { uvs, ..triangle(6.0) }, "uvs".into(), 0, None);
        for i in 0..geometry.triangles.len() {
            let vertices = geometry.triangle_vertices(i);
            for corner in 0..3 {
                let expected = (
                    vertices.p[corner],
                    vertices.n.map_or(Vec3::ZERO, |n| n[corner]),
                    vertices.uv.unwrap_or(DEFAULT_UVS)[corner],
                );
                assert_eq!(geometry.triangle_corner(i, corner), expected, "triangle {i}, corner {corner}");
            }
        }
    }
}
