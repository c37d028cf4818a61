//! An injective UV layout for a mesh whose UV islands overlap (issue 20): its charts packed
//! apart. A UV-keyed F map holds one field per texel, so islands stacked on one another share
//! a field, exact only for mirror-image halves under a mirror-symmetric orientation field
//! (docs/design-decisions.md, "Overlapping UV islands"). Packed apart, every island has its own.
//!
//! Each chart keeps its shape: its UVs are moved and scaled by one factor common to all charts
//! (u' = s (u - low) + corner), so a mirrored chart stays mirrored, and F, derived from the new
//! UVs, carries the texture on the surface as before at the same scale. The charts' bounding
//! boxes are shelf-packed (tallest first) at the largest s that fits the unit square, a margin
//! apart.

use crate::geometry::TriangleMesh;
use glam::Vec2;

/// The mesh with its charts packed apart, and the factor s its UVs were scaled by.
pub struct Repacked {
    /// The same positions, normals and triangles, with the new UVs.
    pub mesh: TriangleMesh,
    /// The factor on every chart's UVs.
    pub scale: f32,
}

/// Pack the charts of `mesh` (`chart_of_triangle`: each triangle's chart, numbered from 0, as
/// [`super::ChartField`] finds them) apart in the unit square, `margin` UV units between
/// neighbouring boxes and from the square's border. An error without UVs, or when the charts
/// cannot be packed at any scale (their margins alone fill the square).
pub fn pack_charts(mesh: &TriangleMesh, chart_of_triangle: &[u32], margin: f32) -> Result<Repacked, String> {
    let uvs = mesh.uvs.as_ref().ok_or("the mesh has no texture coordinates")?;
    let charts = chart_of_triangle.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
    // Each vertex belongs to the chart of the triangles using it (one: a chart is the
    // triangles joined through shared UV vertices); unused vertices to none.
    let mut chart_of_vertex = vec![None; uvs.len()];
    for (tri, &c) in mesh.indices.iter().zip(chart_of_triangle) {
        for &v in tri {
            chart_of_vertex[v as usize] = Some(c as usize);
        }
    }
    let mut boxes = vec![(Vec2::INFINITY, Vec2::NEG_INFINITY); charts];
    for (uv, chart) in uvs.iter().zip(&chart_of_vertex) {
        if let Some(c) = *chart {
            boxes[c] = (boxes[c].0.min(*uv), boxes[c].1.max(*uv));
        }
    }
    let sizes: Vec<Vec2> = boxes.iter().map(|(low, high)| (*high - *low).max(Vec2::ZERO)).collect();
    let mut order: Vec<usize> = (0..charts).collect();
    order.sort_by(|&a, &b| sizes[b].y.total_cmp(&sizes[a].y).then(sizes[b].x.total_cmp(&sizes[a].x)));
    let corners_at = |scale: f32| shelf_pack(order.iter().map(|&c| sizes[c] * scale), margin);
    if corners_at(0.0).is_none() {
        return Err(format!("{charts} UV charts cannot be packed {margin} apart in the unit square"));
    }
    // The largest scale that fits, by bisection; an upper bound is where the largest chart
    // alone fills the square.
    let largest = sizes.iter().map(|s| s.max_element()).fold(0.0f32, f32::max);
    let (mut low, mut high) = (0.0f32, if largest > 0.0 { 1.0 / largest } else { 1.0 });
    for _ in 0..48 {
        let middle = 0.5 * (low + high);
        if corners_at(middle).is_some() {
            low = middle;
        } else {
            high = middle;
        }
    }
    let placed = corners_at(low).expect("the scale found fits");
    let mut corner = vec![Vec2::ZERO; charts];
    for (&c, p) in order.iter().zip(placed) {
        corner[c] = p;
    }
    let new_uvs = uvs
        .iter()
        .zip(&chart_of_vertex)
        .map(|(uv, chart)| chart.map_or(*uv, |c| corner[c] + (*uv - boxes[c].0) * low))
        .collect();
    Ok(Repacked { mesh: TriangleMesh { uvs: Some(new_uvs), ..mesh.clone() }, scale: low })
}

/// Lower-left corners of boxes of `sizes` laid left to right in shelves from the bottom of the
/// unit square, `margin` apart and from its border; None if they do not fit.
fn shelf_pack(sizes: impl Iterator<Item = Vec2>, margin: f32) -> Option<Vec<Vec2>> {
    let (mut x, mut y, mut shelf) = (margin, margin, 0.0f32);
    let mut corners = Vec::new();
    for size in sizes {
        if x + size.x + margin > 1.0 {
            (x, y, shelf) = (margin, y + shelf + margin, 0.0);
        }
        if x + size.x + margin > 1.0 || y + size.y + margin > 1.0 {
            return None;
        }
        corners.push(Vec2::new(x, y));
        (x, shelf) = (x + size.x + margin, shelf.max(size.y));
    }
    Some(corners)
}
