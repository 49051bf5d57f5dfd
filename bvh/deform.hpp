// Deforming meshes: deterministic procedural deformations of a rest mesh (the topology stays, only vertex
// positions move), a cloth grid to wave, and the topology check a frame must pass before a tree is refitted.
#pragma once

#include "mesh.hpp"

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

enum class DeformationKind {
  Twist,    ///< rotation about the longest axis, the angle growing linearly along it
  Bend,     ///< the longest axis bent onto a circular arc, curling towards the shortest axis
  Pulsate,  ///< uniform scaling about the centre of the bounds
  Wave,     ///< a sine wave along the longest axis displacing vertices along the shortest, travelling in time
};

std::string_view to_string(DeformationKind kind);

/// One deformation with its parameters. Every amplitude is relative to the rest mesh's own bounds, so a
/// description works for a mesh in any units. Each oscillates in time: at time t in [0, 1) its strength is
/// amplitude * sin(2 pi cycles t), so t = 0 gives the rest mesh and t -> 1 returns to it. The wave keeps its
/// height and travels instead (cycles wavelengths per unit of time). An amplitude of 0 gives the rest mesh.
struct Deformation {
  DeformationKind kind = DeformationKind::Twist;
  /// Twist: angle (radians) between the two ends. Bend: angle (radians) the whole length turns through.
  /// Pulsate: relative change of scale (0.2: between 0.8 and 1.2 times the rest size), below 1.
  /// Wave: height relative to the longest extent of the bounds.
  double amplitude = 0;
  int cycles = 1;         ///< oscillations (wave: wavelengths travelled) over t in [0, 1), at least 1
  double wavelength = 0;  ///< wave only: relative to the longest extent, > 0
};

/// The default description of each kind (twist pi/2, bend pi/2, pulsate 0.2, wave 0.05 with wavelength 0.5).
Deformation default_deformation(DeformationKind kind);

/// Parses "NAME" or "NAME:key=value,key=value" with NAME one of twist, bend, pulsate, wave and keys
/// amplitude, cycles, wavelength (wave only). Throws std::invalid_argument naming the unknown name or key,
/// the value that is not a number, or the value out of range.
Deformation parse_deformation(std::string_view spec);

/// Throws std::invalid_argument naming the parameter that is out of range (non-finite, cycles < 1, a
/// pulsation amplitude of 1 or more, a wavelength <= 0).
void validate(const Deformation& d);

/// The rest mesh deformed at time t (any finite t; the motion has period 1): same vertex count, same
/// triangles, same name. Pure and deterministic. Throws std::invalid_argument for an empty mesh, a
/// non-finite vertex or t, or an invalid description.
Mesh deform(const Mesh& rest, const Deformation& d, double t);

/// The time of frame `frame` of `frames` frames per period: frame / frames. Throws for frames == 0.
double frame_time(std::size_t frame, std::size_t frames);

/// A flat square cloth in the z = 0 plane over [0, 1]^2: n x n cells of two triangles each, (n+1)^2
/// vertices, 2 n^2 triangles. Throws std::invalid_argument for n == 0 or a grid beyond 2^31 vertices.
Mesh cloth_grid(std::size_t n);

/// Throws std::invalid_argument if `frame` cannot be a frame of the same deforming mesh as `reference`:
/// another vertex count, another triangle count, another triangle's indices (the first differing triangle
/// is named), or a non-finite vertex (named). `frame_label` starts the message (a file name, "frame 3").
void check_same_topology(const Mesh& reference, const Mesh& frame, std::string_view frame_label);

}  // namespace bvhlab
