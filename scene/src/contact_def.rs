//! The contact of a scene resolved to SI ([`ContactDef`]): its indenters and hands, as the
//! TOML scene ([`crate::contact_build::resolve_contact`]) and the LS-DYNA deck give them, and
//! the selection of its contact surface; [`crate::contact_build::build_stage`] turns it into
//! the running contact stage.

use contact::{ContactParams, HandSpec, IndenterSpec};
use std::collections::HashSet;

/// A rigid indenter with the place its definition came from (for messages).
#[derive(Clone, Debug)]
pub struct IndenterDef {
    /// The indenter (SI).
    pub spec: IndenterSpec,
    /// `FILE:LINE` (or `FILE`) of its definition.
    pub origin: String,
}

/// A two-finger hand before it is placed against the skin.
#[derive(Clone, Debug)]
pub struct HandDef {
    /// The hand (SI); `gap` is the given one, or 0.
    pub hand: HandSpec,
    /// Whether the scene gave `gap` (else a hand that starts inside the skin is backed off).
    pub gap_given: bool,
    /// Whether it was placed on a phantom location (then its travel is extended by the
    /// back-off, so that the indentation beyond first contact is the requested one).
    pub placed: bool,
    /// `FILE:LINE` (or `FILE`) of its definition.
    pub origin: String,
}

/// Which boundary faces of the mesh take part in contact: every boundary face, restricted by
/// each selection that is given.
#[derive(Clone, Debug, Default)]
pub struct SurfaceSel {
    /// Only faces whose four nodes are all marked (a node set).
    pub nodes: Option<Vec<bool>>,
    /// Only faces of elements of the marked parts.
    pub parts: Option<Vec<bool>>,
    /// Only these faces (sorted node ids), e.g. an LS-DYNA segment set.
    pub faces: Option<HashSet<[u32; 4]>>,
}

/// The contact of a scene: rigid indenters against the boundary of the mesh.
#[derive(Clone, Debug)]
pub struct ContactDef {
    /// Indenters (before assembly: those given as such; after: every one, hands included, in
    /// history-column order).
    pub indenters: Vec<IndenterDef>,
    /// Hands still to be placed (empty after assembly).
    pub hands: Vec<HandDef>,
    /// The contact surface.
    pub surface: SurfaceSel,
    /// Penalty, friction and search settings; `design_dt = None` takes the run's initial step.
    pub params: ContactParams,
    /// Where the contact was defined and what selects its surface, for the message when the
    /// selection leaves no face (e.g. "scene.toml: `contact`").
    pub origin: String,
    /// The hint given when no face is left.
    pub empty_hint: String,
}
