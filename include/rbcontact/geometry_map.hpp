// rbcontact/geometry_map.hpp: the piecewise-affine geometric map h(mu) of the reference configuration:
// on the cells of body i, x = G_i(mu) xr + t_i(mu). Owns the building blocks (dilation about a point,
// stretch along an axis, translation), their composition per body, and their setup from options:
//   -map_<body> dilation[,stretch,translation...]     blocks applied in this order
//   -map_<body>_<block>_param NAME                     the scene parameter driving the block
//   -map_<body>_<block>_ref VALUE                      parameter value at which the block is identity
//                                                      (default: the parameter's -mu_default)
//   dilation:    -map_<body>_dilation_center x,y[,z]  x -> c + (mu/ref)(x - c)
//   stretch:     -map_<body>_stretch_axis k, -map_<body>_stretch_center c   x_k -> c + (mu/ref)(x_k - c)
//   translation: -map_<body>_translation_dir d1,d2[,d3]                   x -> x + (mu - ref) d
// Extensible in C++: derive from AffineBlock and add it to a body's BodyMap.
#pragma once
#include <petscsys.h>
#include <array>
#include <memory>
#include <string>
#include <vector>
#include "rbcontact/scene.hpp"

namespace rbc {

// x -> G x + t, G row-major 3 x 3 (the leading dim x dim block is used).
struct Affine {
  std::array<PetscReal, 9> G{{1, 0, 0, 0, 1, 0, 0, 0, 1}};
  std::array<PetscReal, 3> t{{0, 0, 0}};
  Affine Then(const Affine &next) const; // next o this
  void   Apply(PetscInt dim, const PetscReal x[], PetscReal y[]) const;
  PetscReal Det(PetscInt dim) const;
  bool   IsIdentity() const;
};

class AffineBlock {
public:
  virtual ~AffineBlock() = default;
  virtual Affine      Evaluate(const std::vector<PetscReal> &mu) const = 0;
  virtual std::string Describe() const = 0;
  // Serialization (ROM file): {type (0 dilation, 1 stretch, 2 translation), param, ref, v0, v1, v2, axis}.
  virtual std::array<PetscReal, 7> Record() const = 0;
};
// The block of a record (nullptr for an unknown type).
std::unique_ptr<AffineBlock> AffineBlockFromRecord(const std::array<PetscReal, 7> &r);

class Dilation : public AffineBlock {
public:
  Dilation(PetscInt param, PetscReal ref, std::array<PetscReal, 3> center) : p_(param), ref_(ref), c_(center) {}
  Affine      Evaluate(const std::vector<PetscReal> &mu) const override;
  std::string Describe() const override;
  std::array<PetscReal, 7> Record() const override;
private:
  PetscInt p_; PetscReal ref_; std::array<PetscReal, 3> c_;
};

class Stretch : public AffineBlock {
public:
  Stretch(PetscInt param, PetscReal ref, PetscInt axis, PetscReal center) : p_(param), ref_(ref), axis_(axis), c_(center) {}
  Affine      Evaluate(const std::vector<PetscReal> &mu) const override;
  std::string Describe() const override;
  std::array<PetscReal, 7> Record() const override;
private:
  PetscInt p_; PetscReal ref_; PetscInt axis_; PetscReal c_;
};

class Translation : public AffineBlock {
public:
  Translation(PetscInt param, PetscReal ref, std::array<PetscReal, 3> dir) : p_(param), ref_(ref), d_(dir) {}
  Affine      Evaluate(const std::vector<PetscReal> &mu) const override;
  std::string Describe() const override;
  std::array<PetscReal, 7> Record() const override;
private:
  PetscInt p_; PetscReal ref_; std::array<PetscReal, 3> d_;
};

// The map of one body: its blocks composed in order (identity if none).
struct BodyMap {
  std::vector<std::unique_ptr<AffineBlock>> blocks;
  Affine Evaluate(const std::vector<PetscReal> &mu) const;
};

class GeometryMap {
public:
  // One BodyMap per body of the scene (same order as scene.bodies).
  PetscErrorCode SetFromOptions(MPI_Comm comm, const SceneSpec &scene);
  Affine Evaluate(PetscInt body, const std::vector<PetscReal> &mu) const;
  bool   IsIdentity() const; // no block on any body
  std::string Describe(const SceneSpec &scene) const;
  // Serialization: one row {body, Record()} per block (8 values), and back.
  std::vector<PetscReal> Records() const;
  PetscErrorCode         FromRecords(PetscInt nbodies, const std::vector<PetscReal> &rec);
  // The options of SetFromOptions against the mesh's dimension: a center or direction with fewer coordinates, a
  // stretch axis beyond it. Collective.
  PetscErrorCode CheckDimension(MPI_Comm comm, PetscInt dim) const;
  std::vector<BodyMap> bodies;

private:
  struct DimNeed {
    std::string option;
    PetscInt    value;       // the number of coordinates given, or the axis
    bool        coordinates; // value >= dim needed, else value < dim
  };
  std::vector<DimNeed> needs_;
};

// The parameter values of a scene as a vector (scene order).
std::vector<PetscReal> ParamValues(const SceneSpec &scene);

} // namespace rbc
