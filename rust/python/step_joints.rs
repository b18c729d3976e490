//! The joints of a scene dict (`coulomb.model.Scene`'s `"joints"` entry, written by
//! `coulomb.joints`): each a dict with `kind` ("revolute", "prismatic", "spherical",
//! "fixed"), `a`, `b` (a body index or None for the world), `anchor`, `axis`, `limits`
//! (`(lo, hi)` or None) and `e`. A scene without the entry has no joints.

use pyo3::prelude::*;
use pyo3::types::PyDict;

use super::super::to_py;
use super::{dicts, item};
use crate::error::CoulombError;
use crate::step::{Joint, JointKind};

/// the joints of scene dict `d` (checked against the scene when the stepper is built).
pub(super) fn joints_from_dict(d: &Bound<'_, PyDict>) -> PyResult<Vec<Joint>> {
    if d.get_item("joints")?.is_none() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    for j in dicts(d, "joints")? {
        let kind: String = item(&j, "kind")?;
        let kind = match kind.as_str() {
            "revolute" => JointKind::Revolute,
            "prismatic" => JointKind::Prismatic,
            "spherical" => JointKind::Spherical,
            "fixed" => JointKind::Fixed,
            other => {
                return Err(to_py(
                    d.py(),
                    CoulombError::InvalidParameter(format!("unknown joint kind {other:?}")),
                ))
            }
        };
        out.push(Joint {
            kind,
            a: item(&j, "a")?,
            b: item(&j, "b")?,
            anchor: item(&j, "anchor")?,
            axis: item(&j, "axis")?,
            limits: item(&j, "limits")?,
            e: item(&j, "e")?,
        });
    }
    Ok(out)
}
