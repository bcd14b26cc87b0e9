//! The node graph: cycles and nodes with two parents are refused, then the default scene
//! is walked from its roots with the node transforms composed into world transforms.

use glam::{Mat4, Quat, Vec3};
use gltf::json;

use crate::mesh::scene::Instance;

use super::{Fail, Importer, invalid};

impl Importer<'_, '_> {
    /// Refuses node cycles and nodes with more than one parent.
    pub(super) fn check_node_graph(&self) -> Result<(), Fail> {
        check_no_cycles(self.root)?;
        check_one_parent_each(self.root)
    }

    /// Walks the default scene, instancing the meshes of its nodes at their world transforms.
    pub(super) fn traverse_scene(&mut self) -> Result<(), Fail> {
        let root = self.root;
        let scene_index = match root.scene {
            Some(index) => index.value(),
            None if !root.scenes.is_empty() => 0,
            None => {
                self.scene.warnings.push("the file defines no scene, so there is nothing to show".to_owned());
                return Ok(());
            }
        };
        let Some(gltf_scene) = root.scenes.get(scene_index) else {
            return invalid(format!("default scene {scene_index} does not exist"));
        };
        let mut reached = vec![false; root.nodes.len()];
        let mut stack: Vec<(usize, Mat4)> = Vec::new();
        for node in gltf_scene.nodes.iter().rev() {
            stack.push((node.value(), Mat4::IDENTITY));
        }
        let mut non_triangle = 0usize;
        let mut triangles = 0u64;
        while let Some((index, parent_world)) = stack.pop() {
            let Some(node) = root.nodes.get(index) else {
                return invalid(format!("scene {scene_index} refers to node {index}, which does not exist"));
            };
            match reached.get_mut(index) {
                Some(seen) if *seen => {
                    return invalid(format!(
                        "node {} is reached twice from scene {scene_index} (listed as a scene root and also a child, or listed twice)",
                        node_label(root, index)
                    ));
                }
                Some(seen) => *seen = true,
                None => {}
            }
            let local = local_transform(node).ok_or_else(|| {
                Fail::Invalid(format!("node {} has a non-finite or invalid transform", node_label(root, index)))
            })?;
            let world = parent_world * local;
            if !world.is_finite() {
                return invalid(format!(
                    "node {}: the composed world transform is non-finite",
                    node_label(root, index)
                ));
            }
            if let Some(mesh) = node.mesh
                && let Some(mesh_index) = self.mesh_for(mesh.value(), &mut non_triangle)?
            {
                let mesh_triangles = self.scene.meshes.get(mesh_index as usize).map_or(0, |m| m.triangles.len());
                triangles = triangles.saturating_add(mesh_triangles as u64);
                if triangles <= self.limits.max_triangles {
                    self.scene.instances.push(Instance { mesh: mesh_index, world_from_local: world });
                }
            }
            for child in node.children.iter().flatten().rev() {
                stack.push((child.value(), world));
            }
        }
        if triangles > self.limits.max_triangles {
            return invalid(format!(
                "scene {scene_index} instances {triangles} triangles, more than the {} allowed ({})",
                self.limits.max_triangles, self.limits.reason
            ));
        }
        if non_triangle > 0 {
            self.scene
                .warnings
                .push(format!("skipped {non_triangle} point/line primitive(s) (only triangles are imported)"));
        }
        if self.scene.instances.is_empty() {
            self.scene.warnings.push(format!("scene {scene_index} contains no triangles"));
        }
        Ok(())
    }

    /// Instances every mesh not instanced yet at the identity (tests only).
    pub(super) fn instance_every_mesh(&mut self) -> Result<(), Fail> {
        let mut non_triangle = 0;
        for index in 0..self.root.meshes.len() {
            if self.mesh_map.contains_key(&index) {
                continue;
            }
            if let Some(mesh) = self.mesh_for(index, &mut non_triangle)? {
                self.scene.instances.push(Instance { mesh, world_from_local: Mat4::IDENTITY });
            }
        }
        Ok(())
    }
}

/// Refuses node cycles (and children that do not exist).
fn check_no_cycles(root: &json::Root) -> Result<(), Fail> {
    let nodes = &root.nodes;
    // Cycle detection: iterative depth-first search with three colours.
    let mut colour = vec![0u8; nodes.len()]; // 0 new, 1 on the current path, 2 done
    for start in 0..nodes.len() {
        if colour.get(start) != Some(&0) {
            continue;
        }
        let mut stack: Vec<(usize, usize)> = vec![(start, 0)];
        if let Some(c) = colour.get_mut(start) {
            *c = 1;
        }
        while let Some(&mut (node, ref mut next_child)) = stack.last_mut() {
            let children = nodes.get(node).and_then(|n| n.children.as_deref()).unwrap_or(&[]);
            if let Some(child) = children.get(*next_child) {
                *next_child += 1;
                let child = child.value();
                match colour.get(child) {
                    None => {
                        return invalid(format!(
                            "node {} has child {child}, which does not exist",
                            node_label(root, node)
                        ));
                    }
                    Some(1) => {
                        return invalid(format!(
                            "node hierarchy has a cycle: node {} is its own ancestor (reached again from node {})",
                            node_label(root, child),
                            node_label(root, node)
                        ));
                    }
                    Some(0) => {
                        if let Some(c) = colour.get_mut(child) {
                            *c = 1;
                        }
                        stack.push((child, 0));
                    }
                    Some(_) => {}
                }
            } else {
                if let Some(c) = colour.get_mut(node) {
                    *c = 2;
                }
                stack.pop();
            }
        }
    }
    Ok(())
}

/// Refuses nodes listed as the child of two nodes: glTF nodes form trees.
fn check_one_parent_each(root: &json::Root) -> Result<(), Fail> {
    let nodes = &root.nodes;
    let mut parent: Vec<Option<usize>> = vec![None; nodes.len()];
    for (index, node) in nodes.iter().enumerate() {
        for child in node.children.iter().flatten() {
            let child = child.value();
            let Some(slot) = parent.get_mut(child) else {
                continue;
            };
            if let Some(previous) = *slot {
                return invalid(format!(
                    "node {} has two parents (nodes {previous} and {index}); glTF nodes must form trees",
                    node_label(root, child)
                ));
            }
            *slot = Some(index);
        }
    }
    Ok(())
}

fn node_label(root: &json::Root, index: usize) -> String {
    match root.nodes.get(index).and_then(|n| n.name.as_deref()) {
        Some(name) => format!("{index} ({name:?})"),
        None => index.to_string(),
    }
}

/// The node's local transform (matrix, or translation * rotation * scale), or `None`
/// when it is not finite.
fn local_transform(node: &json::Node) -> Option<Mat4> {
    let matrix = if let Some(matrix) = node.matrix {
        Mat4::from_cols_array(&matrix)
    } else {
        let translation = Vec3::from_array(node.translation.unwrap_or([0.0; 3]));
        let rotation = match node.rotation {
            Some(rotation) => {
                let q = Quat::from_array(rotation.0);
                if !q.is_finite() || q.length_squared() == 0.0 {
                    return None;
                }
                q.normalize()
            }
            None => Quat::IDENTITY,
        };
        let scale = Vec3::from_array(node.scale.unwrap_or([1.0; 3]));
        Mat4::from_scale_rotation_translation(scale, rotation, translation)
    };
    matrix.is_finite().then_some(matrix)
}
