//! Named f32/f64 tensors to and from a `.safetensors` file (little-endian, as the format says),
//! with the format's `__metadata__` (string to string) in the header.

use crate::dataset::write_atomic;
use crate::error::{Error, Result};
use safetensors::tensor::{Dtype, SafeTensors, TensorView};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

/// Data of one tensor.
#[derive(Clone, Debug, PartialEq)]
pub enum TensorData {
    /// Single precision.
    F32(Vec<f32>),
    /// Double precision.
    F64(Vec<f64>),
}

/// One tensor: shape (row-major) and data.
#[derive(Clone, Debug, PartialEq)]
pub struct Tensor {
    /// Shape, row-major.
    pub shape: Vec<usize>,
    /// Values.
    pub data: TensorData,
}

/// Tensors by name.
pub type TensorSet = BTreeMap<String, Tensor>;

/// Writes `tensors` and the header's `__metadata__` to `path` atomically.
pub fn write_tensors(
    path: &Path,
    tensors: &TensorSet,
    metadata: &BTreeMap<String, String>,
) -> Result<()> {
    let bytes: Vec<(String, Dtype, Vec<usize>, Vec<u8>)> = tensors
        .iter()
        .map(|(name, t)| {
            let (dtype, b) = match &t.data {
                TensorData::F32(v) => {
                    (Dtype::F32, v.iter().flat_map(|x| x.to_le_bytes()).collect())
                }
                TensorData::F64(v) => {
                    (Dtype::F64, v.iter().flat_map(|x| x.to_le_bytes()).collect())
                }
            };
            (name.clone(), dtype, t.shape.clone(), b)
        })
        .collect();
    let views = bytes
        .iter()
        .map(|(n, d, s, b)| {
            TensorView::new(*d, s.clone(), b)
                .map(|v| (n.clone(), v))
                .map_err(|e| Error::format(path, format!("tensor {n}: {e}")))
        })
        .collect::<Result<Vec<_>>>()?;
    let meta: std::collections::HashMap<String, String> = metadata
        .iter()
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    let buf = safetensors::serialize(views, (!meta.is_empty()).then_some(meta))
        .map_err(|e| Error::format(path, format!("serialising: {e}")))?;
    write_atomic(path, |mut f| {
        f.write_all(&buf).map_err(|e| Error::io(path, e))
    })
}

/// The header's `__metadata__` of `path` (empty when it has none).
pub fn read_metadata(path: &Path) -> Result<BTreeMap<String, String>> {
    let buf = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let (_, m) = SafeTensors::read_metadata(&buf)
        .map_err(|e| Error::format(path, format!("not a safetensors file: {e}")))?;
    Ok(m.metadata()
        .clone()
        .map(|h| h.into_iter().collect())
        .unwrap_or_default())
}

/// Reads every tensor of `path` (f32 and f64 only).
pub fn read_tensors(path: &Path) -> Result<TensorSet> {
    let buf = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let st = SafeTensors::deserialize(&buf)
        .map_err(|e| Error::format(path, format!("not a safetensors file: {e}")))?;
    let mut out = TensorSet::new();
    for (name, view) in st.tensors() {
        let data = match view.dtype() {
            Dtype::F32 => TensorData::F32(
                view.data()
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                    .collect(),
            ),
            Dtype::F64 => TensorData::F64(
                view.data()
                    .chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
                    .collect(),
            ),
            other => {
                return Err(Error::format(
                    path,
                    format!("tensor {name}: dtype {other:?}, expected F32 or F64"),
                ))
            }
        };
        out.insert(
            name,
            Tensor {
                shape: view.shape().to_vec(),
                data,
            },
        );
    }
    Ok(out)
}

/// Takes tensor `name` with `shape` as f32 values; the error names the file and tensor.
pub fn take_f32(set: &mut TensorSet, path: &Path, name: &str, shape: &[usize]) -> Result<Vec<f32>> {
    match take(set, path, name, shape)? {
        TensorData::F32(v) => Ok(v),
        TensorData::F64(v) => Ok(v.into_iter().map(|x| x as f32).collect()),
    }
}

/// Takes tensor `name` with `shape` as f64 values; the error names the file and tensor.
pub fn take_f64(set: &mut TensorSet, path: &Path, name: &str, shape: &[usize]) -> Result<Vec<f64>> {
    match take(set, path, name, shape)? {
        TensorData::F64(v) => Ok(v),
        TensorData::F32(v) => Ok(v.into_iter().map(f64::from).collect()),
    }
}

fn take(set: &mut TensorSet, path: &Path, name: &str, shape: &[usize]) -> Result<TensorData> {
    let t = set
        .remove(name)
        .ok_or_else(|| Error::format(path, format!("missing tensor {name}")))?;
    if t.shape != shape {
        return Err(Error::format(
            path,
            format!("tensor {name}: shape {:?}, expected {shape:?}", t.shape),
        ));
    }
    Ok(t.data)
}
