//! The cubed-sphere hexahedral mesh of a granule (physics.md §3): an n×n×n
//! core block plus m shell layers of 6·n² elements each, nodes placed by an
//! equiangular, blended map, outer nodes on the true sphere.
//!
//! n = 8, m = 2 gives the standard 1280 hexes / 1501 nodes; n = 4, m = 1 the
//! coarse 160-hex level; n = 16, m = 4 the fine one.
//!
//! Node numbering: the (n+1)³ core lattice points first (index
//! i + (n+1)(j + (n+1)k)), then each shell layer l = 1..m in turn, holding the
//! 6n²+2 boundary lattice points in lattice order. The outer surface nodes are
//! therefore the last 6n²+2 nodes.

use core::fmt;

use crate::element::hex8::{self, FLIP, HexCoords};
use crate::tensor::{Mat3, det_mat};
use crate::{Real, math};

/// Resolution and node-placement parameters of a cubed-sphere mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SphereMeshParams {
    /// Sphere radius R, m.
    pub radius: Real,
    /// Core divisions n per cube edge; even, 2 ≤ n ≤ 64.
    pub n: u32,
    /// Shell layers m; 1 ≤ m ≤ 32.
    pub m: u32,
    /// Core radius factor r_c (core corner at R·r_c·…).
    pub core_radius: Real,
    /// Core blending weight w_c between cube (0) and sphere (1).
    pub core_weight: Real,
    /// Blending weight at mid-shell (layer fraction ½).
    pub mid_weight: Real,
}

impl SphereMeshParams {
    /// The recommended placement (r_c = 0.6, w_c = 0.5, w = 0.8 at mid-shell)
    /// at resolution (n, m) for radius `radius` (m).
    pub fn new(radius: Real, n: u32, m: u32) -> Self {
        Self {
            radius,
            n,
            m,
            core_radius: 0.6,
            core_weight: 0.5,
            mid_weight: 0.8,
        }
    }

    /// The standard granule mesh: d = 1 mm, n = 8, m = 2.
    pub fn standard() -> Self {
        Self::new(0.5e-3, 8, 2)
    }

    /// Buffer sizes this mesh needs, or an error for an invalid resolution.
    pub fn size(&self) -> Result<MeshSize, MeshError> {
        let (n, m) = (self.n as usize, self.m as usize);
        let ok =
            self.n.is_multiple_of(2) && (2..=64).contains(&self.n) && (1..=32).contains(&self.m);
        if !ok {
            return Err(MeshError::InvalidResolution {
                n: self.n,
                m: self.m,
            });
        }
        if !(self.radius > 0.0 && self.radius.is_finite()) {
            return Err(MeshError::InvalidParameter {
                field: "radius",
                value: self.radius,
                allowed: "finite, > 0 m",
            });
        }
        let surface = 6 * n * n + 2;
        Ok(MeshSize {
            nodes: (n + 1).pow(3) + m * surface,
            hexes: n.pow(3) + 6 * n * n * m,
            quads: 6 * n * n,
            surface_nodes: surface,
            scratch: (n + 1).pow(3),
        })
    }

    /// (radius factor r, blending weight w) of shell layer `l` in 1..=m:
    /// r grows linearly from r_c to 1, w piecewise linearly through
    /// (0, w_c), (½, w_mid), (1, 1) in the layer fraction l/m.
    fn shell_layer(&self, l: u32) -> (Real, Real) {
        let rho = l as Real / self.m as Real;
        let r = self.core_radius + (1.0 - self.core_radius) * rho;
        let w = if rho <= 0.5 {
            self.core_weight + (self.mid_weight - self.core_weight) * 2.0 * rho
        } else {
            self.mid_weight + (1.0 - self.mid_weight) * (2.0 * rho - 1.0)
        };
        (r, w)
    }
}

/// Buffer sizes of a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshSize {
    /// Nodes.
    pub nodes: usize,
    /// Hexahedra.
    pub hexes: usize,
    /// Outer surface quads.
    pub quads: usize,
    /// Outer surface nodes (the last `surface_nodes` nodes).
    pub surface_nodes: usize,
    /// Entries of the `u32` scratch buffer the generator needs.
    pub scratch: usize,
}

/// Why a mesh could not be generated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MeshError {
    /// The sphere's n odd or out of 2..=64, or m out of 1..=32.
    InvalidResolution {
        /// Core divisions.
        n: u32,
        /// Shell layers.
        m: u32,
    },
    /// A scalar out of its range: the sphere's radius, the cube's divisions
    /// or side.
    InvalidParameter {
        /// The argument or field.
        field: &'static str,
        /// The value given.
        value: Real,
        /// The allowed range.
        allowed: &'static str,
    },
    /// A buffer has the wrong length.
    BufferLength {
        /// Buffer name.
        buffer: &'static str,
        /// Entries expected.
        expected: usize,
        /// Entries given.
        got: usize,
    },
    /// A hex or quad names a node beyond the positions, or more surface
    /// nodes are declared than there are nodes.
    NodeOutOfRange {
        /// "hexes", "quads" or "surface_nodes".
        buffer: &'static str,
        /// Index of the hex or quad (0 for `surface_nodes`).
        index: usize,
        /// The node id (or the surface node count).
        id: usize,
        /// Nodes in the mesh.
        nodes: usize,
    },
    /// A surface quad names a node that is not a surface node (an id below
    /// the first of the last `surface_nodes` nodes, which every per-node
    /// surface table is indexed from).
    NotSurfaceNode {
        /// Index of the quad.
        quad: usize,
        /// The node id.
        id: usize,
        /// The first surface node's id.
        first_surface: usize,
    },
    /// An element has a corner with det J ≤ 0 (bad placement parameters).
    InvertedElement {
        /// Element index.
        element: usize,
        /// Corner (node slot 0..8).
        corner: usize,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidResolution { n, m } => write!(
                f,
                "invalid sphere mesh resolution n = {n}, m = {m}: n must be even in 2..=64, m in 1..=32"
            ),
            Self::InvalidParameter {
                field,
                value,
                allowed,
            } => write!(f, "invalid mesh `{field}` = {value}: allowed {allowed}"),
            Self::BufferLength {
                buffer,
                expected,
                got,
            } => write!(
                f,
                "mesh buffer `{buffer}` has {got} entries, expected {expected}"
            ),
            Self::NodeOutOfRange {
                buffer,
                index,
                id,
                nodes,
            } => write!(
                f,
                "mesh `{buffer}` entry {index} names node {id}, but there are {nodes} nodes (ids 0..{nodes})"
            ),
            Self::NotSurfaceNode {
                quad,
                id,
                first_surface,
            } => write!(
                f,
                "mesh `quads` entry {quad} names node {id}, which is not a surface node (those are \
                 ids {first_surface} on)"
            ),
            Self::InvertedElement { element, corner } => {
                write!(f, "mesh element {element} is inverted at corner {corner}")
            }
        }
    }
}

impl core::error::Error for MeshError {}

/// Caller-provided output buffers of [`generate`], sized by
/// [`SphereMeshParams::size`].
pub struct MeshBuffers<'a> {
    /// Out: reference node positions `[node][xyz]`, m.
    pub positions: &'a mut [[Real; 3]],
    /// Out: hex connectivity, 8 node ids each in [`hex8`] order, positive volume.
    pub hexes: &'a mut [[u32; 8]],
    /// Out: outer surface quads, 4 node ids counter-clockwise seen from outside.
    pub quads: &'a mut [[u32; 4]],
    /// Out: for each surface node s (node id = nodes − surface_nodes + s), the
    /// ids of the quads that contain it, `u32::MAX` for unused slots (a node
    /// has 3 or 4 quads).
    pub node_quads: &'a mut [[u32; 4]],
    /// Scratch: `size().scratch` entries, contents undefined on return.
    pub scratch: &'a mut [u32],
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

/// Generates the mesh into `out`. Returns the sizes written, or an error;
/// every element corner is checked for det J > 0.
pub fn generate(p: &SphereMeshParams, out: &mut MeshBuffers<'_>) -> Result<MeshSize, MeshError> {
    let size = p.size()?;
    check_len("positions", out.positions.len(), size.nodes)?;
    check_len("hexes", out.hexes.len(), size.hexes)?;
    check_len("quads", out.quads.len(), size.quads)?;
    check_len("node_quads", out.node_quads.len(), size.surface_nodes)?;
    check_len("scratch", out.scratch.len(), size.scratch)?;
    let lattice = Lattice::new(p, size, out.scratch);
    place_nodes(p, &lattice, out.positions);
    connect_hexes(&lattice, out.positions, out.hexes)?;
    connect_surface(&lattice, out.positions, out.quads, out.node_quads);
    Ok(size)
}

/// Lattice bookkeeping: node ids of (i, j, k, layer).
struct Lattice<'s> {
    n: usize,
    m: usize,
    surface: usize,
    /// Boundary index of each lattice point (boundary points only).
    boundary: &'s mut [u32],
}

impl<'s> Lattice<'s> {
    fn new(p: &SphereMeshParams, size: MeshSize, scratch: &'s mut [u32]) -> Self {
        let n = p.n as usize;
        let lattice = Self {
            n,
            m: p.m as usize,
            surface: size.surface_nodes,
            boundary: scratch,
        };
        let mut b = 0u32;
        for k in 0..=n {
            for j in 0..=n {
                for i in 0..=n {
                    let id = lattice.lattice_id([i, j, k]);
                    lattice.boundary[id] = if lattice.on_boundary([i, j, k]) {
                        b += 1;
                        b - 1
                    } else {
                        u32::MAX
                    };
                }
            }
        }
        lattice
    }

    fn lattice_id(&self, c: [usize; 3]) -> usize {
        c[0] + (self.n + 1) * (c[1] + (self.n + 1) * c[2])
    }

    fn on_boundary(&self, c: [usize; 3]) -> bool {
        c.iter().any(|&x| x == 0 || x == self.n)
    }

    /// Node id of lattice point `c` in layer `l` (0 = core; l ≥ 1 needs a
    /// boundary point).
    fn node(&self, c: [usize; 3], l: usize) -> u32 {
        let id = self.lattice_id(c);
        if l == 0 {
            id as u32
        } else {
            ((self.n + 1).pow(3) + (l - 1) * self.surface) as u32 + self.boundary[id]
        }
    }

    /// Lattice point of face (axis, side) at in-face indices (p, q).
    fn face_point(&self, axis: usize, side: usize, p: usize, q: usize) -> [usize; 3] {
        let mut c = [0; 3];
        c[axis] = side;
        c[(axis + 1) % 3] = p;
        c[(axis + 2) % 3] = q;
        c
    }
}

/// Position of lattice point `c` with radius factor `r` and blend `w`
/// (`None`: the core rule r = r_c ξ∞, w = w_c ξ∞).
fn position(p: &SphereMeshParams, c: [usize; 3], shell: Option<(Real, Real)>) -> [Real; 3] {
    let half = (p.n / 2) as Real;
    let xi: [Real; 3] = core::array::from_fn(|a| (c[a] as Real - half) / half);
    let inf = math::max(
        math::abs(xi[0]),
        math::max(math::abs(xi[1]), math::abs(xi[2])),
    );
    if inf == 0.0 {
        return [0.0; 3];
    }
    // Direction on the cube surface, equiangular: d ← tan(π d / 4); ±1 stays ±1.
    let d: [Real; 3] = core::array::from_fn(|a| {
        let t = xi[a] / inf;
        if math::abs(t) == 1.0 {
            t
        } else {
            math::tan(core::f64::consts::FRAC_PI_4 * t)
        }
    });
    let len = math::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    let (r, w) = shell.unwrap_or((p.core_radius * inf, p.core_weight * inf));
    core::array::from_fn(|a| p.radius * r * ((1.0 - w) * d[a] + w * d[a] / len))
}

fn place_nodes(p: &SphereMeshParams, lat: &Lattice<'_>, x: &mut [[Real; 3]]) {
    let n = lat.n;
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let c = [i, j, k];
                x[lat.node(c, 0) as usize] = position(p, c, None);
                if lat.on_boundary(c) {
                    for l in 1..=lat.m {
                        x[lat.node(c, l) as usize] = position(p, c, Some(p.shell_layer(l as u32)));
                    }
                }
            }
        }
    }
}

fn gather(x: &[[Real; 3]], ids: &[u32; 8]) -> HexCoords {
    core::array::from_fn(|i| x[ids[i] as usize])
}

/// Reorders `ids` to a right-handed hex if its centre Jacobian is negative,
/// then checks all eight corners.
fn orient(x: &[[Real; 3]], ids: [u32; 8], element: usize) -> Result<[u32; 8], MeshError> {
    let centre: Mat3 = hex8::jacobian(&gather(x, &ids), [0.0; 3]);
    let ids = if det_mat(&centre) < 0.0 {
        core::array::from_fn(|i| ids[FLIP[i]])
    } else {
        ids
    };
    let coords = gather(x, &ids);
    for corner in 0..8 {
        let scaled = hex8::corner_scaled_jacobian(&coords, corner);
        if scaled.is_nan() || scaled <= 0.0 {
            return Err(MeshError::InvertedElement { element, corner });
        }
    }
    Ok(ids)
}

fn connect_hexes(
    lat: &Lattice<'_>,
    x: &[[Real; 3]],
    hexes: &mut [[u32; 8]],
) -> Result<(), MeshError> {
    let n = lat.n;
    let mut e = 0;
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let ids = core::array::from_fn(|s| {
                    let sg = hex8::NODE_SIGNS[s];
                    let d = |v: Real| usize::from(v > 0.0);
                    lat.node([i + d(sg[0]), j + d(sg[1]), k + d(sg[2])], 0)
                });
                hexes[e] = orient(x, ids, e)?;
                e += 1;
            }
        }
    }
    for axis in 0..3 {
        for side in [0, n] {
            for q in 0..n {
                for p in 0..n {
                    for l in 0..lat.m {
                        let quad = face_quad(lat, axis, side, p, q);
                        let ids = core::array::from_fn(|s| lat.node(quad[s % 4], l + s / 4));
                        hexes[e] = orient(x, ids, e)?;
                        e += 1;
                    }
                }
            }
        }
    }
    Ok(())
}

/// The four lattice points of face cell (p, q), counter-clockwise in (p, q).
fn face_quad(lat: &Lattice<'_>, axis: usize, side: usize, p: usize, q: usize) -> [[usize; 3]; 4] {
    [
        lat.face_point(axis, side, p, q),
        lat.face_point(axis, side, p + 1, q),
        lat.face_point(axis, side, p + 1, q + 1),
        lat.face_point(axis, side, p, q + 1),
    ]
}

fn connect_surface(
    lat: &Lattice<'_>,
    x: &[[Real; 3]],
    quads: &mut [[u32; 4]],
    node_quads: &mut [[u32; 4]],
) {
    let n = lat.n;
    let first_surface = lat.node(lat.face_point(0, 0, 0, 0), lat.m) - lat.boundary[0];
    node_quads.fill([u32::MAX; 4]);
    let mut f = 0;
    for axis in 0..3 {
        for side in [0, n] {
            for q in 0..n {
                for p in 0..n {
                    let pts = face_quad(lat, axis, side, p, q);
                    let mut ids: [u32; 4] = core::array::from_fn(|s| lat.node(pts[s], lat.m));
                    let v = |id: u32| x[id as usize];
                    let (x0, x1, x3) = (v(ids[0]), v(ids[1]), v(ids[3]));
                    let e1 = [x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]];
                    let e3 = [x3[0] - x0[0], x3[1] - x0[1], x3[2] - x0[2]];
                    let normal = [
                        e1[1] * e3[2] - e1[2] * e3[1],
                        e1[2] * e3[0] - e1[0] * e3[2],
                        e1[0] * e3[1] - e1[1] * e3[0],
                    ];
                    let centre: [Real; 3] =
                        core::array::from_fn(|a| ids.iter().map(|&id| v(id)[a]).sum::<Real>());
                    if normal[0] * centre[0] + normal[1] * centre[1] + normal[2] * centre[2] < 0.0 {
                        ids = [ids[0], ids[3], ids[2], ids[1]];
                    }
                    quads[f] = ids;
                    for id in ids {
                        let slots = &mut node_quads[(id - first_surface) as usize];
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
