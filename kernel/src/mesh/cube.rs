//! A hex-meshed cube of side a centred at the origin, n×n×n equal hexes: the
//! body of the friction oracle (physics.md §5.6 item 5: a cube slides where
//! a sphere would roll).
//!
//! The layouts are those of the sphere ([`MeshBuffers`]): hexes in
//! [`hex8`] order with positive volume, outer quads counter-clockwise seen
//! from outside, `node_quads` per surface node (3 quads at a corner, 4
//! elsewhere).
//!
//! Node numbering: the (n−1)³ interior lattice points first, then the
//! 6n²+2 surface lattice points, each group in lattice order (i fastest,
//! then j, then k). The outer surface nodes are therefore the last nodes.

use crate::Real;
use crate::element::hex8;
use crate::mesh::sphere::{MeshBuffers, MeshError, MeshSize};

/// Largest divisions per edge (keeps node ids in `u32` with room to spare).
pub const MAX_DIVISIONS: u32 = 256;
// The range is spelled out in `cube_size`'s error.
const _: () = assert!(MAX_DIVISIONS == 256);

/// Buffer sizes of a cube with `n` divisions per edge, or
/// [`MeshError::InvalidParameter`] (`n`) unless 1 ≤ n ≤
/// [`MAX_DIVISIONS`]. `scratch` is one entry per lattice point.
pub fn cube_size(n: u32) -> Result<MeshSize, MeshError> {
    if !(1..=MAX_DIVISIONS).contains(&n) {
        return Err(MeshError::InvalidParameter {
            field: "n",
            value: Real::from(n),
            allowed: "1 <= n <= 256 divisions per edge",
        });
    }
    let n = n as usize;
    let surface = 6 * n * n + 2;
    Ok(MeshSize {
        nodes: (n + 1).pow(3),
        hexes: n.pow(3),
        quads: 6 * n * n,
        surface_nodes: surface,
        scratch: (n + 1).pow(3),
    })
}

fn check_len(buffer: &'static str, got: usize, expected: usize) -> Result<(), MeshError> {
    if got == expected {
        Ok(())
    } else {
        Err(MeshError::BufferLength {
            buffer,
            expected,
            got,
        })
    }
}

/// Generates the cube of side `side` (m, finite and > 0) with `n` divisions
/// per edge into `out` (sized by [`cube_size`]). Returns the sizes written;
/// an invalid `n` or `side` gives [`MeshError::InvalidParameter`] naming it,
/// a wrong buffer length [`MeshError::BufferLength`]. Every element corner
/// is checked for det J > 0.
pub fn generate_cube(side: Real, n: u32, out: &mut MeshBuffers<'_>) -> Result<MeshSize, MeshError> {
    let size = cube_size(n)?;
    if !(side > 0.0 && side.is_finite()) {
        return Err(MeshError::InvalidParameter {
            field: "side",
            value: side,
            allowed: "finite, > 0 m",
        });
    }
    check_len("positions", out.positions.len(), size.nodes)?;
    check_len("hexes", out.hexes.len(), size.hexes)?;
    check_len("quads", out.quads.len(), size.quads)?;
    check_len("node_quads", out.node_quads.len(), size.surface_nodes)?;
    check_len("scratch", out.scratch.len(), size.scratch)?;
    let n = n as usize;
    let mut lattice = Lattice {
        n,
        ids: out.scratch,
    };
    lattice.number(size.nodes - size.surface_nodes);
    lattice.place(side, out.positions);
    lattice.connect_hexes(out.positions, out.hexes)?;
    lattice.connect_surface(size.nodes - size.surface_nodes, out.quads, out.node_quads);
    Ok(size)
}

/// The (n+1)³ lattice and its node ids (held in the caller's scratch).
struct Lattice<'s> {
    n: usize,
    /// Node id of each lattice point, in lattice order.
    ids: &'s mut [u32],
}

impl Lattice<'_> {
    fn lattice_id(&self, c: [usize; 3]) -> usize {
        c[0] + (self.n + 1) * (c[1] + (self.n + 1) * c[2])
    }

    fn on_surface(&self, c: [usize; 3]) -> bool {
        c.iter().any(|&x| x == 0 || x == self.n)
    }

    fn node(&self, c: [usize; 3]) -> u32 {
        self.ids[self.lattice_id(c)]
    }

    /// Interior points get 0.., surface points `first_surface`.., each in
    /// lattice order.
    fn number(&mut self, first_surface: usize) {
        let n = self.n;
        let (mut interior, mut surface) = (0u32, first_surface as u32);
        for k in 0..=n {
            for j in 0..=n {
                for i in 0..=n {
                    let c = [i, j, k];
                    let id = self.lattice_id(c);
                    let next = if self.on_surface(c) {
                        &mut surface
                    } else {
                        &mut interior
                    };
                    self.ids[id] = *next;
                    *next += 1;
                }
            }
        }
    }

    fn place(&self, side: Real, x: &mut [[Real; 3]]) {
        let n = self.n;
        // (2i − n)/(2n)·a: exact zero at the centre, exact ±a/2 at the faces.
        let coord = |i: usize| side * (2.0 * i as Real - n as Real) / (2.0 * n as Real);
        for k in 0..=n {
            for j in 0..=n {
                for i in 0..=n {
                    x[self.node([i, j, k]) as usize] = [coord(i), coord(j), coord(k)];
                }
            }
        }
    }

    fn connect_hexes(&self, x: &[[Real; 3]], hexes: &mut [[u32; 8]]) -> Result<(), MeshError> {
        let n = self.n;
        let mut e = 0;
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let ids: [u32; 8] = core::array::from_fn(|s| {
                        let sg = hex8::NODE_SIGNS[s];
                        let d = |v: Real| usize::from(v > 0.0);
                        self.node([i + d(sg[0]), j + d(sg[1]), k + d(sg[2])])
                    });
                    let coords = core::array::from_fn(|s| x[ids[s] as usize]);
                    for corner in 0..8 {
                        let scaled = hex8::corner_scaled_jacobian(&coords, corner);
                        if scaled.is_nan() || scaled <= 0.0 {
                            return Err(MeshError::InvertedElement { element: e, corner });
                        }
                    }
                    hexes[e] = ids;
                    e += 1;
                }
            }
        }
        Ok(())
    }

    /// Lattice point of face (axis, side) at in-face indices (p, q) along
    /// the axes axis+1 and axis+2 (cyclic), so that +p × +q = +axis.
    fn face_point(axis: usize, side: usize, p: usize, q: usize) -> [usize; 3] {
        let mut c = [0; 3];
        c[axis] = side;
        c[(axis + 1) % 3] = p;
        c[(axis + 2) % 3] = q;
        c
    }

    fn connect_surface(
        &self,
        first_surface: usize,
        quads: &mut [[u32; 4]],
        node_quads: &mut [[u32; 4]],
    ) {
        let n = self.n;
        node_quads.fill([u32::MAX; 4]);
        let mut f = 0;
        for axis in 0..3 {
            for side in [0, n] {
                for q in 0..n {
                    for p in 0..n {
                        let ids: [u32; 4] = [
                            self.node(Self::face_point(axis, side, p, q)),
                            self.node(Self::face_point(axis, side, p + 1, q)),
                            self.node(Self::face_point(axis, side, p + 1, q + 1)),
                            self.node(Self::face_point(axis, side, p, q + 1)),
                        ];
                        // Counter-clockwise about +axis; the face at side 0
                        // looks along −axis, so reverse it there.
                        let ids = if side == 0 {
                            [ids[0], ids[3], ids[2], ids[1]]
                        } else {
                            ids
                        };
                        quads[f] = ids;
                        for id in ids {
                            let slots = &mut node_quads[id as usize - first_surface];
                            if let Some(slot) = slots.iter_mut().find(|s| **s == u32::MAX) {
                                *slot = f as u32;
                            }
                        }
                        f += 1;
                    }
                }
            }
        }
    }
}
