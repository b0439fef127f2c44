"""Plane geometry in local metres: polylines (lists of (x, y)), polygons and rectangles."""
import math


def dist_point_segment(p, a, b):
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / length2))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


def dist_point_polyline(p, line):
    if len(line) == 1:
        return math.hypot(p[0] - line[0][0], p[1] - line[0][1])
    return min(dist_point_segment(p, line[i], line[i + 1]) for i in range(len(line) - 1))


def point_in_polygon(p, poly):
    """Even-odd rule; poly is a ring without the closing point."""
    x, y = p
    inside = False
    n = len(poly)
    for i in range(n):
        (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % n]
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def dist_point_polygon(p, poly):
    """0 inside, else the distance to the ring."""
    if point_in_polygon(p, poly):
        return 0.0
    return dist_point_polyline(p, list(poly) + [poly[0]])


def length(line):
    return sum(math.hypot(line[i + 1][0] - line[i][0], line[i + 1][1] - line[i][1]) for i in range(len(line) - 1))


def point_at(line, s):
    """(x, y, heading) at arc length s (clamped to the line)."""
    s = max(0.0, s)
    for i in range(len(line) - 1):
        (x0, y0), (x1, y1) = line[i], line[i + 1]
        seg = math.hypot(x1 - x0, y1 - y0)
        if s <= seg or i == len(line) - 2:
            t = 0.0 if seg == 0.0 else min(1.0, s / seg)
            return x0 + t * (x1 - x0), y0 + t * (y1 - y0), math.atan2(y1 - y0, x1 - x0)
        s -= seg
    x, y = line[-1]
    return x, y, 0.0


def sub_line(line, s0, s1):
    """The part of the polyline between arc lengths s0 < s1."""
    out = [point_at(line, s0)[:2]]
    acc = 0.0
    for i in range(len(line) - 1):
        acc += math.hypot(line[i + 1][0] - line[i][0], line[i + 1][1] - line[i][1])
        if s0 < acc < s1:
            out.append(tuple(line[i + 1]))
    out.append(point_at(line, s1)[:2])
    return out


def offset(line, d):
    """The polyline moved by d to its left (negative: right), with mitred corners."""
    if len(line) < 2:
        return list(line)
    normals = []
    for i in range(len(line) - 1):
        dx, dy = line[i + 1][0] - line[i][0], line[i + 1][1] - line[i][1]
        n = math.hypot(dx, dy) or 1.0
        normals.append((-dy / n, dx / n))
    out = []
    for i, (x, y) in enumerate(line):
        if i == 0:
            nx, ny = normals[0]
        elif i == len(line) - 1:
            nx, ny = normals[-1]
        else:
            ax, ay = normals[i - 1]
            bx, by = normals[i]
            mx, my = ax + bx, ay + by
            m = math.hypot(mx, my)
            if m < 1e-9:
                nx, ny = bx, by
            else:
                mx, my = mx / m, my / m
                cos_half = mx * ax + my * ay
                scale = 1.0 / max(cos_half, 0.3)
                nx, ny = mx * scale, my * scale
        out.append((x + d * nx, y + d * ny))
    return out


def rectangle(cx, cy, heading, length_m, width_m):
    """Corners of a length x width rectangle centred on (cx, cy), its length along heading (radians)."""
    c, s = math.cos(heading), math.sin(heading)
    return [(cx + c * dx - s * dy, cy + s * dx + c * dy)
            for dx, dy in ((-length_m / 2, -width_m / 2), (length_m / 2, -width_m / 2),
                           (length_m / 2, width_m / 2), (-length_m / 2, width_m / 2))]


def ring_samples(poly, step=1.0):
    """Points every `step` metres along the ring, corners included."""
    pts = []
    n = len(poly)
    for i in range(n):
        (x0, y0), (x1, y1) = poly[i], poly[(i + 1) % n]
        k = max(1, int(math.ceil(math.hypot(x1 - x0, y1 - y0) / step)))
        pts.extend((x0 + (x1 - x0) * j / k, y0 + (y1 - y0) * j / k) for j in range(k))
    return pts


def polygons_clear(a, b, clearance):
    """True when the polygons a and b are at least `clearance` apart (sampled every 0.5 m)."""
    return all(dist_point_polygon(p, b) >= clearance for p in ring_samples(a, 0.5)) and \
        all(dist_point_polygon(p, a) >= clearance for p in ring_samples(b, 0.5))


def segment_intersection(p, q, r, s):
    """The intersection point of the segments pq and rs, or None."""
    d = (q[0] - p[0]) * (s[1] - r[1]) - (q[1] - p[1]) * (s[0] - r[0])
    if abs(d) < 1e-12:
        return None
    t = ((r[0] - p[0]) * (s[1] - r[1]) - (r[1] - p[1]) * (s[0] - r[0])) / d
    u = ((r[0] - p[0]) * (q[1] - p[1]) - (r[1] - p[1]) * (q[0] - p[0])) / d
    if -1e-9 <= t <= 1 + 1e-9 and -1e-9 <= u <= 1 + 1e-9:
        return p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])
    return None
