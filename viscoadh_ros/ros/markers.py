"""Markers for RViz/Foxglove: the contact disc and the indenter, in the contact frame.

The contact frame's origin is the centre of the contact on the undeformed surface, z points
from the body out through the indenter, so the indenter tip sits at ``z = -depth``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from visualization_msgs.msg import Marker

from viscoadh_ros.ros.conversions import ns_to_stamp

if TYPE_CHECKING:
    from viscoadh_ros.core.config import IndenterConfig
    from viscoadh_ros.core.simulator import StepOutput

#: Thickness of the drawn contact disc as a fraction of its radius (a flat, visible disc).
_DISC_THICKNESS = 0.02


def _marker(kind: int, marker_id: int, namespace: str, stamp_ns: int, frame_id: str) -> Marker:
    marker = Marker(type=kind, id=marker_id, ns=namespace, action=Marker.ADD)
    marker.header.stamp = ns_to_stamp(stamp_ns)
    marker.header.frame_id = frame_id
    marker.pose.orientation.w = 1.0
    marker.color.a = 0.8
    return marker


def contact_markers(
    output: StepOutput,
    indenter: IndenterConfig,
    *,
    contact_id: str,
    stamp_ns: int,
    frame_id: str,
) -> list[Marker]:
    """The contact disc (CYLINDER of the contact radius; DELETE when out of contact) and, for a
    sphere or a flat punch, the indenter (SPHERE / CYLINDER) at its current depth."""
    disc = _marker(Marker.CYLINDER, 0, contact_id, stamp_ns, frame_id)
    if output.contact_radius > 0.0:
        diameter = 2.0 * output.contact_radius
        disc.scale.x = disc.scale.y = diameter
        disc.scale.z = _DISC_THICKNESS * diameter
        disc.color.r, disc.color.g = 1.0, 0.3
    else:
        disc.action = Marker.DELETE
    markers = [disc]
    if indenter.shape in ("sphere", "flat_punch"):
        kind = Marker.SPHERE if indenter.shape == "sphere" else Marker.CYLINDER
        body = _marker(kind, 1, contact_id, stamp_ns, frame_id)
        radius = indenter.radius
        body.scale.x = body.scale.y = body.scale.z = 2.0 * radius
        # Sphere: centre one radius above the tip. Punch: a cylinder as tall as it is wide,
        # its face at the tip.
        body.pose.position.z = radius - output.depth
        body.color.r = body.color.g = body.color.b = 0.6
        markers.append(body)
    return markers
