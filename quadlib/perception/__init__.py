"""Perception for navigation without GPS: a 2D lidar in a map of walls, and scan matching (ICP)."""

from .icp import IcpResult, best_rigid_transform, estimate_normals, icp, point_to_plane_step
from .lidar import LidarScan, corridor_map, lidar_scan, room_map

__all__ = ["IcpResult", "LidarScan", "best_rigid_transform", "corridor_map", "estimate_normals", "icp", "lidar_scan",
           "point_to_plane_step", "room_map"]
