//! Point-to-mesh distances as the fit's measures compute them, for the peer check
//! `bench/peers/trimesh_distance.py`.
//!
//! Usage: `mesh_distance MESH.{obj,stl,ply} POINTS.csv` (one `x,y,z` per line); prints one
//! line per point: `distance,qx,qy,qz` (the closest point of the mesh).

use pdeshape::fit::{InputMesh, MeshDistance, MeshFormat};
use pdeshape::Vec3;

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().filter(|a| a != "--bench").collect();
    if args.len() != 3 {
        return Err("usage: mesh_distance MESH POINTS.csv".into());
    }
    let format = std::path::Path::new(&args[1])
        .extension()
        .and_then(|e| e.to_str())
        .and_then(MeshFormat::from_extension)
        .ok_or("mesh: extension must be obj, stl, ply or off")?;
    let bytes = std::fs::read(&args[1]).map_err(|e| e.to_string())?;
    let mesh = InputMesh::read(&bytes, format).map_err(|e| e.to_string())?;
    let index = MeshDistance::new(&mesh);
    let text = std::fs::read_to_string(&args[2]).map_err(|e| e.to_string())?;
    let mut out = String::new();
    for (k, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let v: Vec<f64> = line
            .split(',')
            .map(|s| s.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{}:{}: {e}", args[2], k + 1))?;
        if v.len() != 3 {
            return Err(format!("{}:{}: expected x,y,z", args[2], k + 1));
        }
        let (d, q, _) = index
            .closest(Vec3::new(v[0], v[1], v[2]))
            .ok_or("empty mesh")?;
        out += &format!("{d:e},{:e},{:e},{:e}\n", q.x, q.y, q.z);
    }
    print!("{out}");
    Ok(())
}
