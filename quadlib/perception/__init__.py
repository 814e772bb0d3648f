"""Perception for navigation without GPS: scan matching (ICP)."""

from .icp import IcpResult, best_rigid_transform, estimate_normals, icp, point_to_plane_step

__all__ = ["IcpResult", "best_rigid_transform", "estimate_normals", "icp", "point_to_plane_step"]
