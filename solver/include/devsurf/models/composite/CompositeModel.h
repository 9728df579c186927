#pragma once

#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/engine/Normalization.h"
#include "devsurf/engine/Problem.h"
#include "devsurf/io/CreasePattern.h"
#include "devsurf/io/IgesWriter.h"
#include "devsurf/io/QuadMesh.h"
#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/composite/CompositeHinges.h"
#include "devsurf/models/composite/CompositeTopology.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/LinearPoints.h"
#include "devsurf/terms/SofteningWeight.h"

namespace devsurf::models::composite {

/// Which normals a composite's crease rows (000_… eqs. 7/8) compare.
enum class CreaseNormals {
  /// Ruling from CompositeOptions::rulingCreaseUnknowns unknowns on, Free below.
  Auto,
  /// Each face's normal at the crease from the geometry: the crease tangent × the face's ruling
  /// there (terms::CurvedFoldRulingTerm). The rows hold control points only, so the free normals
  /// stay per face and are eliminated per sample before the factorization (issue 17).
  Ruling,
  /// The faces' free normal variables (terms::CurvedFoldTerm, Tang et al.'s formulation): the
  /// rows couple the normals of neighbouring faces, which then stay in the factorized system.
  Free,
};

/// How the 2D vertices of the development (development management, 000_… §5) are solved.
enum class DevelopmentSolve {
  /// In one system with the surface, as Tang et al. do: every iteration factorizes both together.
  Coupled,
  /// In a system of their own (engine::VariableLayout::setAlternating): each iteration steps the
  /// surface with the development held, then the development with the surface held, each system
  /// factorized apart (the development's reused across iterations while CG converges with it).
  /// A 40 × 40 sheet iterates in about half the coupled time (issue 17), but the two converge
  /// only linearly toward each other: a flat sheet pulled into a fold can shrink in its plane
  /// instead of folding (the pleated sheet preset ends flat), so it is not the default.
  Alternating,
};

/// Weights and switches of the composite model (the strip model's, applied to every face).
struct CompositeOptions {
  double developabilityWeight = 1.0;  ///< hard rows: developability (eq. 4), planarity, creases (eqs. 7/8), smoothness
  double unitNormalWeight = 0.1;      ///< soft unit length of the normals not held hard
  /// ε_reg² multiplier of the normals (see StripOptions). 1e-3 rather than the strip's 1e-4: a
  /// composite's crease rows couple two faces' normals, and with the smaller scale a
  /// perturbed fold creeps back along its crease ends (measured on the closed-form cylinder
  /// crease, 100 perturbations: 97 of 100 back to 1e-6 in 20 iterations at 1e-4, all at 1e-3).
  double normalRegularizationScale = 1e-3;
  bool normalize = true;              ///< centre and scale to unit size while solving (003_… §5.5)
  /// Weight softening near face boundaries (003_… §5.5, Fig. 5.1): the crease rows (eq. 7/8) of
  /// an S edge at parameter u are multiplied by terms::softeningWeight of u normalized to the
  /// edge's domain — 0 near both ends, rising to 1 between ξ2 and ξ3. (0, 0, 1, 1) = off.
  terms::SofteningBreakpoints softening = {0.0, 0.0, 1.0, 1.0};
  engine::LinearSolverKind linearSolver = engine::LinearSolverKind::Auto;
  /// Weight of the soft "fold_angle" rows (design.foldAngles; radians against the handles' unit
  /// size): strong enough that the slider folds the sheet, soft so that a drag still wins.
  double foldWeight = 1.0;
  /// Weight of the soft "development_crease" rows: the development samples of an interior S edge
  /// drawn in the development domain (a crease of an imported drawing) stay near its curve.
  double developmentCreaseWeight = 1.0;
  /// Degeneracy guards (ARCHITECTURE §8), hard terms whose rows vanish until a shape degenerates:
  /// "ruling_length" (terms::RulingLengthTerm: no ruling of a strip-like face shrinks below this
  /// fraction of its length when the model was built; 0 = off), ...
  double rulingGuardRatio = 0.35;
  /// ... "strip_width" (terms::StripWidthTerm: the area element |(b − a) × (a′ + b′)| of every
  /// strip-like face, and each side's |(b − a) × a′|, |(b − a) × b′|, keep this fraction of their
  /// values at build time: no collapse across the rulings, no crease turning into its rulings
  /// (sliver quads that fold over); 0 = off) ...
  double widthGuardRatio = 0.25;
  /// ... "development_orientation" (terms::TriangleOrientationTerm: every triangle of the
  /// development keeps at least this fraction of its signed area at build time, so no face of the
  /// development turns over; 0 = off) ...
  double developmentAreaRatio = 0.1;
  /// ... and "crease_backtrack" (terms::PolygonBacktrackTerm: no two legs of an S edge's control
  /// polygon within one span's reach point more than 90° apart where they did not at build time)
  /// with "crease_leg_length" (terms::RulingLengthTerm on the legs: none shrinks below
  /// legGuardRatio of its length at build time); false = off.
  bool creaseBacktrackGuard = true;
  double legGuardRatio = 0.25;
  /// Normal splines (000_… §2.2, §7): the normals of a strip-like face are a cubic spline with
  /// one control point per control point of the face's curves (C² on the face's own knots when
  /// they are cubic), evaluated linearly at the parameters where the equations need a normal,
  /// instead of one free vector per parameter. About a seventh of the normal unknowns (Tang et
  /// al. used them in 8 of the 10 rows of Fig. 17: "reducing computation times to almost half");
  /// the unit length is held hard at the first control point, soft at the others.
  bool normalSplines = false;
  /// The normals the crease rows compare (see CreaseNormals). Auto: Tang's rows on free normals for
  /// designs of the size people draw and fold (they are the more forgiving far from a solution and
  /// in a developed sheet's drag, docs/architecture.md), the ruling rows from
  /// rulingCreaseUnknowns on, where the factorization of the free normals dominates an iteration
  /// (a 10 × 40 sheet, 9 870 unknowns: 10 ms of it with free normals, 1.7 ms without).
  CreaseNormals creaseNormals = CreaseNormals::Auto;
  int rulingCreaseUnknowns = 5000;
  /// How the development's vertices are solved (see DevelopmentSolve).
  DevelopmentSolve developmentSolve = DevelopmentSolve::Coupled;
  /// With DevelopmentSolve::Alternating: the development block's multiplier of ε_reg². The
  /// development's own system is well posed (its anchors fix the rigid motion), and at 1 its step
  /// is damped so much that the development lags behind the surface (pleated sheet: development
  /// length error 0.56 % after its 40 iterations; 4e-6 at 0.01).
  double alternatingDevelopmentRegularizationScale = 0.01;
  /// Whoever builds the model gives up here (a job's time limit, a session's budget): checked
  /// while the faces, the development mesh and its unfolding are built and the pattern analyzed;
  /// once passed, the constructor throws engine::DeadlineExceeded. Solves have their own
  /// (engine::SolverOptions::deadline). Default: never.
  engine::Deadline deadline;
};

/// An interior edge of the composite as extracted: where it runs and how it is folded.
///
/// Fold angle convention (the FOLD format's edges_foldAngle): seen from the side the face normals
/// point to — the side from which every face's boundary runs counterclockwise — a valley fold has
/// a positive angle, a mountain fold a negative one; 0 is flat, ±180° folded flat. At each sample,
/// with t the unit tangent of the edge from v0 to v1 and n1, n2 the unit normals of the face that
/// runs along v0→v1 (EdgeInfo::faces[0]) and of the other face, θ = atan2(⟨t, n1×n2⟩, ⟨n1, n2⟩)
/// is the rotation of n1 to n2 about t; θ > 0 turns the second face away from the normals' side
/// (mountain), so foldAngleDeg = −θ in degrees.
struct CreaseGeometry {
  int edge = -1;
  EdgeType type = EdgeType::Spline;
  CreaseKind kind = CreaseKind::None;
  Eigen::MatrixX3d polyline;    ///< samples from v0 to v1 (2 for an R edge)
  Eigen::VectorXd foldAngleDeg; ///< per sample, valley > 0
  char assignment = 'F';        ///< 'M', 'V' (sign of the mean fold angle) or 'F' (|mean| < 0.01°)
};

/// Sampled geometry (design coordinates) for drawing and export.
struct CompositeGeometry {
  /// Per face: strip-like faces as a (U × vSamples) grid of s(u, v) (U = spans·samplesPerSpan + 1,
  /// quads with a degenerate side where a ruling degenerates); planar faces as a fan of quads
  /// (centroid, corner, edge midpoint, next corner). Quads run counterclockwise seen from the
  /// face normal.
  std::vector<io::QuadMesh> faces;
  /// All faces in one mesh; vertices are not shared between faces, so creases stay sharp and
  /// degenerate rulings remain valid (index-distinct) quads.
  io::QuadMesh merged;
  std::vector<CreaseGeometry> creases;  ///< every interior edge
};

/// Quality measures (000_… Fig. 17) of the current state; report names in brackets.
///
/// They are taken on the auxiliary mesh of 000_… §5: every strip-like face sampled at
/// U = spans·samplesPerSpan + 1 parameters equally spaced over its domain, one quad per pair of
/// consecutive rulings (a(u_i), a(u_i+1), b(u_i+1), b(u_i)), planar faces as their polygon; the
/// samples along shared edges are shared.
struct CompositeQuality {
  double faceFlatnessMax = 0.0;    ///< [face_flatness_max] δ = distance of the diagonals' lines /
                                   ///< mean of the two shortest edges, per quad; planar faces:
                                   ///< largest distance of a corner from their least-squares
                                   ///< plane / mean of their two shortest edges
                                   ///< (metrics::polygonFlatness); triangles 0
  double faceFlatnessMean = 0.0;   ///< [face_flatness_mean]
  double vertexCurvatureMax = 0.0; ///< [vertex_curvature_max] |angle sum − 2π| at interior vertices (rad)
  double creaseFoldResidualMax = 0.0;  ///< [crease_fold_residual_max] max over the samples of
                                   ///< "fold"/"geodesic" creases of |⟨c′, n1 ± n2⟩|/|c′| and
                                   ///< |⟨c″, n1 ± n2⟩|/|c″| (eq. 7/8 rows scaled as Tang's free-normal
                                   ///< rows, 003_… §5.2.4, at every sample including the crease's
                                   ///< ends, with the surfaces' unit normals: a check independent of
                                   ///< the solver's CurvedFoldRulingTerm rows, which it does not share)
  double warpAngleMaxDeg = 0.0;    ///< [warp_angle_max_deg] over all strip-like faces (1000 rulings each)
  double warpAngleMeanDeg = 0.0;   ///< [warp_angle_mean_deg]
  double foldAngleMaxDeg = 0.0;    ///< [crease_fold_angle_max_deg] max |fold angle| over interior edges
  int quads = 0;
  int interiorVertices = 0;
  /// Per composite vertex: |angle sum − 2π| (rad) on the auxiliary mesh, 0 at boundary vertices
  /// (for colouring).
  std::vector<double> vertexCurvature;
  /// Per face: the largest δ of its quads (planar faces: metrics::polygonFlatness of the face).
  std::vector<double> faceFlatness;
};

/// The sampled mesh of development management (design.developmentSamples > 0) and its planar
/// development.
///
/// Vertices: the composite's vertices first, then the interior samples of every S edge (in edge
/// order, stored direction); every S edge of a strip-like face is sampled at U = spans·samples + 1
/// equally spaced parameters, rulings only at their ends, so a strip face is a U×2 grid, a cone a
/// fan to its apex, a planar face its polygon. Shared edges share their samples.
struct CompositeDevelopment {
  /// A pair of sample vertices whose distance the development keeps (eq. 12).
  enum class PairKind {
    Spline,    ///< segment `segment` (stored direction) of S edge `edge`
    Ruling,    ///< the composite's R edge `edge`
    Interior,  ///< a sampled ruling inside face `face` (a_i b_i, or a_i to a cone's apex)
    Diagonal,  ///< a diagonal of a sampled quad of face `face` (or of a planar polygon)
  };
  struct Pair {
    int v0 = -1, v1 = -1;
    PairKind kind = PairKind::Diagonal;
    int edge = -1, segment = -1, face = -1;
  };
  Eigen::MatrixX3d vertices3d;  ///< design coordinates
  Eigen::MatrixX2d vertices2d;  ///< development, design units
  std::vector<std::vector<int>> polygons;  ///< sampled quads (triangles where a ruling degenerates), planar faces; CCW
  std::vector<int> polygonFace;             ///< composite face of each polygon
  std::vector<Pair> pairs;                  ///< every edge and diagonal, each once
  std::vector<int> vertexSource;            ///< ≥ 0: composite vertex; −1: an S edge sample
  int anchor0 = -1, anchor1 = -1;           ///< fixed vertex (both coordinates) and the one with fixed y
                                            ///< (not fixed when the design prescribes a domain)
  /// With a seam (CompositeDesign::developmentSeam): per seam sample {vertex, its copy on the
  /// other side}; vertices2d(copy) = vertices2d(vertex) + period.
  std::vector<std::array<int, 2>> periodic;
  Eigen::Vector2d period = Eigen::Vector2d::Zero();  ///< T, design units (zero without a seam)
};

/// Composite developables of Tang et al. 2016 §3 / Mundilova ch. 5: faces that are ruled spline
/// developables, cones and planar polygons, joined along creases (curved folds, eq. 7), geodesic
/// seams (eq. 8) or smoothly.
///
/// Setup/solve split as StripModel: the constructor validates, builds variables and terms and
/// analyzes the topology once; solve() runs iterations; handle targets move without re-analysis.
///
/// Variables (normalized coordinates): block "vertex i" (3) per vertex, "edge e points" per S edge
/// with interior control points (3 each), "face f normals" (3 per evaluation parameter) per
/// strip-like face, "face f normal" (3) per planar face. A face's curves are linear in the shared
/// blocks (terms::LinearPoints with offset 0 whose columns are 3D points of x), so a reversed S
/// edge is a permutation of columns and an S edge's ends are its vertices' blocks.
///
/// Evaluation parameters of a strip-like face: both ends of the domain and 3m−2 per span
/// (000_… §2.1) — the ends give every ruling edge a normal for smoothness and folds there.
/// Terms: "developability" (hard, per strip-like face; cones included: their third row vanishes),
/// "planarity" (hard, PlanarPolygonTerm), "unit_normal_hard" (first normal of every face),
/// "unit_normal" (soft), "crease_fold"/"crease_geodesic" (hard: CurvedFoldRulingTerm at the edge's
/// 3m − 2 parameters per span by default, CurvedFoldTerm at all its parameters with
/// CreaseNormals::Free), "smooth" (hard, NormalMatchTerm along S edges or at R edges labelled smooth),
/// "fairness" (soft, decaying, per S edge including its end vertices), "handle" (soft),
/// "vertex_developability" (hard, per interior vertex that is not a cone apex: the angles between
/// the first control-polygon legs of its edges sum to 2π, 000_… §5 "Local developability in
/// vertices").
class CompositeModel {
 public:
  /// @throws std::invalid_argument naming the path ("faces[2]: …", "fixed[0].index: …")
  explicit CompositeModel(CompositeDesign design, CompositeOptions options = {});
  ~CompositeModel();
  /// Not movable: the solver keeps a reference to this model's problem.
  CompositeModel(CompositeModel&&) = delete;
  CompositeModel& operator=(CompositeModel&&) = delete;

  /// The checks the constructor makes (topology and references), without building anything.
  /// @throws std::invalid_argument
  static void validateDesign(const CompositeDesign& design);

  engine::SolveSummary solve(const engine::SolverOptions& options);

  /// The current design (design coordinates); fixed points are returned exactly as given.
  CompositeDesign design() const;
  const CompositeOptions& options() const { return options_; }
  /// True if the crease rows hold the faces' ruling normals (CreaseNormals::Ruling, or Auto at this
  /// model's size), false if they compare free normals.
  bool rulingCreases() const { return rulingCreases_; }
  const CompositeTopology& topology() const { return *topology_; }

  /// Sets the weight of handle `i` (0 releases it without rebuilding the model).
  void setHandleWeight(int i, double weight);
  /// [ruling_length_min_ratio] the narrowest ruling of any strip-like face at its evaluation
  /// parameters over its length when the model was built (1 when nothing is guarded).
  double rulingLengthMinRatio() const;
  /// [strip_width_min_ratio] the smallest area element |(b − a) × (a′ + b′)| of any strip-like
  /// face at its evaluation parameters over its value when the model was built (1 when nothing
  /// is guarded).
  double stripWidthMinRatio() const;
  /// [crease_backtrack_max] over every S edge's control polygon: max(0, −cos θ) of its sharpest
  /// turn θ between consecutive legs (0 unless a polygon turns by more than 90°).
  double creaseBacktrackMax() const;
  /// Moves handle `i` (design coordinates); no re-analysis.
  void setHandleTarget(int i, const Eigen::Vector3d& position);
  /// Re-initializes all normals from the current geometry.
  void resetNormals();

  /// The metrics of the current state. Remembered until the variables change, so a session that
  /// streams an iterate (geometry, its metrics, a checkpoint) measures each state once.
  CompositeQuality quality(int samplesPerSpan = 10) const;
  CompositeGeometry geometry(int samplesPerSpan = 16, int vSamples = 3) const;
  /// Whether the model manages a development (design.developmentSamples > 0).
  bool hasDevelopment() const { return developmentBlock_ >= 0; }
  /// The sampled mesh and its development (current state).
  /// @throws std::logic_error without a development
  CompositeDevelopment development() const;
  /// The development's period T (design units) when it is cut open along a seam; |T| is the
  /// circumference of the cylinder it wraps onto. Zero without a seam.
  Eigen::Vector2d developmentPeriod() const;
  /// Polygons of the development that are not counterclockwise (signed area ≤ 0): the isometry
  /// rows (distances only) cannot tell a face from its mirror image, so a large change — a crease
  /// switched from fold to smooth, say — can leave faces overfolded (000_… §5).
  int flippedDevelopmentFaces() const;
  /// Replaces the development by a fresh unfolding of the current surface, placed by the rigid
  /// motion that best fits the current development (fixed coordinates keep their values). solve()
  /// calls it when it ends with flipped faces. Returns whether anything changed.
  bool repairDevelopment();
  /// [development_length_error] sqrt(Σ(l3 − l2)²)/sqrt(Σ l3²) over all pairs (sampled edges and
  /// quad diagonals) of the sampled mesh (l3) and the development (l2). 0 without a development.
  double developmentLengthError() const;
  /// [development_edge_strain_max] max |l3 − l2| / l2 over the sampled edges (the crease
  /// pattern's edges: quad diagonals left out) — where developmentLengthError, weighted by l3²,
  /// hides a short edge stretched by a few percent. 0 without a development.
  double developmentEdgeStrainMax() const;
  /// Unfolds the current 3D sampled mesh face after face (BFS over faces through shared edges,
  /// each quad as two triangles keeping its edges and one diagonal), anchor0 at the origin and
  /// anchor1 on the +x axis; design units. What the development variables start from.
  Eigen::MatrixX2d unfoldedDevelopment() const;
  /// The crease pattern of the development: vertices2d/vertices3d of development(), edges =
  /// sampled edges (boundary B; interior S edges and R edges M/V by the sign of their fold angle
  /// per segment (creases(samples)), F when |angle| < 1e-6° or the edge is labelled "smooth"
  /// (and then CreaseEdge::proposed: read back, it stays smooth); seam edges B; sampled rulings
  /// inside faces F),
  /// faces = polygons, rulings = the sampled interior rulings, curves = every S edge (id = edge
  /// index).
  /// @throws std::logic_error without a development
  io::CreasePattern creasePattern(const std::string& title = {}) const;
  /// The composite as IGES entities (design units): every strip-like face as a B-spline surface of
  /// degree (m, 1) (entity 128; u along a and b in the face's direction, v across the rulings,
  /// v = 0 on a, so the control net is a's points then b's), every planar face as bilinear
  /// patches (centroid, corner, edge midpoint, next corner), every S edge as a curve (entity 126).
  /// Labels: "F<face>", "F<face>P<k>", "E<edge>".
  void igesEntities(std::vector<io::IgesSurface>& surfaces, std::vector<io::IgesCurve>& curves) const;
  /// Every interior edge with its fold angles (remembered like quality()).
  std::vector<CreaseGeometry> creases(int samplesPerSpan = 16) const;

  /// A hinge of the creases (see FoldHinge) and its current fold angle.
  struct HingeAngle {
    int edge = -1;
    int end = 0;
    double angleDeg = 0.0;  ///< + valley, − mountain
  };
  /// Every hinge with its current fold angle (what the fold slider takes as 100 % when a design
  /// has no fold-angle targets yet).
  std::vector<HingeAngle> hingeAngles() const;
  /// Moves the "fold_angle" targets to amount × design.foldAngles (0 = flat, 1 = the targets);
  /// no re-analysis (CompositeCreaseFolding.cpp).
  /// @throws std::invalid_argument unless 0 ≤ amount ≤ 1
  void setFoldAmount(double amount);
  double foldAmount() const { return design_.foldAmount; }
  /// Whether the design has fold-angle targets (model.fold_angles), at any amount.
  bool hasFoldTargets() const { return !design_.foldAngles.empty(); }
  /// Takes the current fold angles as the targets at the current amount (each target becomes
  /// angle / amount, within ±180°), so what a drag made of the fold is what the slider now holds;
  /// no re-analysis. At amount 0 (a flat design a drag folded) the amount first becomes what the
  /// drag folded: the largest ratio of a hinge's angle to its target, at most 1 — nothing happens
  /// if no hinge folded. A hinge folded by less than 0.5°, or against the sign of its target, keeps
  /// its target.
  /// @return whether a target or the amount changed (the design's scene then differs from the
  ///         one clients were last sent).
  bool captureFoldTargets();
  /// Lets go of the fold-angle targets (weight 0: a drag may change the fold) or holds them again
  /// (their weight, options.foldWeight); no re-analysis.
  void holdFoldTargets(bool held);
  /// [fold_angle_error_max_deg] the largest |θ − amount·θ*| over the fold-angle targets, degrees
  /// (0 without targets).
  double foldAngleErrorMaxDeg() const;

  /// Curves a and b of a strip-like face in the direction of u (design coordinates; a cone's b is
  /// the constant apex).
  std::pair<spline::BSplineCurve, spline::BSplineCurve> faceCurves(int f) const;
  /// Unit normal of face f at parameter u (strip-like) from the geometry: (a′ + b′) × (b − a), or
  /// a′ × b′ where the ruling degenerates; planar faces: the polygon's (Newell) normal.
  Eigen::Vector3d faceNormal(int f, double u) const;

  const std::vector<double>& evaluationParameters(int f) const { return faceParams_.at(f); }
  engine::Problem& problem() { return problem_; }
  const engine::Problem& problem() const { return problem_; }
  engine::GuidedProjectionSolver& solver() { return *solver_; }
  int numUnknowns() const { return problem_.layout().numFree(); }

 private:
  struct FaceRows {
    terms::LinearPoints a, da, b, db;  ///< at the face's parameters, columns = points of x
  };
  void buildProblem();
  /// Interior vertex v's star for vertex developability (000_… §5): the point indices of the
  /// control points next to v along its edges (S edges: c₁; R edges: the other vertex), in order
  /// around v; empty for boundary vertices and cone apices.
  std::vector<int> vertexStar(int v) const;
  void addVertexDevelopabilityTerms();
  /// Point index of the control point next to vertex v on edge e (S edges: c₁ from v's end; R
  /// edges and S edges without interior points: the other vertex).
  int neighbourPoint(int e, int v) const;
  /// Interior S edge e seen from its two faces at its interior parameters (the crease rows'
  /// parameters): a′ there, each face's ruling b − a, and the sign that orients a′ × (b − a) like
  /// that face's normal.
  struct CreaseSides {
    std::vector<double> params;
    terms::LinearPoints da;
    std::array<terms::LinearPoints, 2> across;
    std::array<std::vector<double>, 2> orientation;
  };
  CreaseSides creaseSides(int e) const;
  /// The crease rows of interior S edge e with the faces' normals from their rulings (CreaseNormals::Ruling).
  void addRulingCreaseTerm(int e);
  /// The smooth rows of edge e (S or R) with both faces' normals from their tangent planes
  /// (terms::RulingNormalMatchTerm; CreaseNormals::Ruling, both faces strip-like).
  void addRulingSmoothTerm(int e);
  bool rulingCreases_ = false;
  void addTangentContinuityTerms();
  /// The soft "fold_angle" rows of design.foldAngles (CompositeCreaseFolding.cpp).
  void addFoldAngleTerm();
  std::vector<FoldHinge> hinges_;       ///< every hinge (built with the problem)
  std::vector<int> foldTargetHinge_;    ///< per design.foldAngles entry: its hinge
  int foldTerm_ = -1;                   ///< the "fold_angle" term, or −1
  std::vector<int> vertexTerms_;
  void initializeNormals();
  /// Osculating-plane normals of "straight" S edges: a′ × n of the face beside the edge.
  void initializeOsculatingNormals();
  std::vector<int> oscBlock_;  ///< per edge: osculating normals of a "straight" S edge, or −1
  /// Index of a slot's 3D point in x (x offset / 3).
  int pointIndex(const PointSlot& s) const;
  PointSlot slotOf(const PointRef& r) const;
  terms::LinearPoints curveRows(const spline::KnotVector& knots, const std::vector<PointSlot>& slots,
                                const std::vector<double>& params, int derivative) const;
  /// Normals of strip-like face f at the parameters of S edge e (stored direction) or at one
  /// ruling end (end = 0, 1); a planar face's normal.
  terms::LinearPoints normalsAlongEdge(int f, int e) const;
  terms::LinearPoints normalAtRuling(int f, int e) const;
  Eigen::Vector3d pointValue(const PointSlot& s) const;  ///< design coordinates
  Eigen::Vector3d normalVariable(int f, int k) const;
  /// The normals of face f at its parameters faceParams_[f] as linear points of its normal block:
  /// the identity (free vectors) or the normal spline's evaluation matrix.
  terms::LinearPoints faceNormals(int f) const;

  CompositeDesign design_;
  CompositeOptions options_;
  CompositeQuality computeQuality(int samplesPerSpan) const;
  /// creases(samplesPerSpan); with `foldResidualMax`, also the largest crease-row residual of the
  /// fold and geodesic S edges at the same samples (CompositeQuality::creaseFoldResidualMax).
  std::vector<CreaseGeometry> computeCreases(int samplesPerSpan, double* foldResidualMax = nullptr) const;
  struct CreaseSamples {
    std::vector<CreaseGeometry> creases;
    double foldResidualMax = 0.0;
  };
  /// computeCreases with its residual, remembered like quality().
  CreaseSamples creaseSamples(int samplesPerSpan) const;
  /// quality() and creases() of the variables they were computed from (CompositeModel.cpp).
  struct StateCache;
  mutable std::unique_ptr<StateCache> stateCache_;

  std::unique_ptr<CompositeTopology> topology_;
  engine::Normalization normalization_;
  /// x when the model was built: a point still there reads back as design_ gives it (pointValue).
  Eigen::VectorXd builtPoints_;
  engine::Problem problem_;
  std::unique_ptr<engine::GuidedProjectionSolver> solver_;
  std::vector<int> vertexBlock_, edgeBlock_, normalBlock_;
  std::vector<std::vector<double>> faceParams_;
  std::vector<FaceRows> faceRows_;
  /// Per strip-like face with options_.normalSplines: K×M evaluation of its normal spline at
  /// faceParams_[f]; empty otherwise (free vectors).
  std::vector<spline::EvaluationMatrix> normalSplineRows_;
  std::vector<int> handleTerms_;
  std::vector<int> rulingTerms_, widthTerms_;  ///< degeneracy guards "ruling_length", "strip_width" per face
  double scale_ = 1.0;  ///< bounding-box diagonal of the input (design coordinates)
  // development management
  void buildDevelopmentMesh();
  void addDevelopmentTerms();
  Eigen::MatrixX2d unfold(const Eigen::VectorXd& x) const;  ///< normalized units
  int developmentBlock_ = -1;
  int periodBlock_ = -1;                    ///< T, with a seam
  std::vector<bool> seamEdge_;              ///< per edge: cut open in the development
  std::vector<std::array<int, 2>> devPeriodic_;  ///< (vertex, copy) development ids
  /// Per edge and side (faces[0], faces[1]): its samples from v0 to v1 as development vertices.
  std::vector<std::array<std::vector<int>, 2>> devEdgeSamples_;
  CompositeDevelopment devMesh_;  ///< combinatorics (coordinates filled on demand)
  terms::LinearPoints devSpatial_;  ///< 3D sample vertices, columns = points of x
  std::vector<std::array<int, 3>> devTriangles_;
  std::vector<int> devTriangleFace_;
};

}  // namespace devsurf::models::composite
