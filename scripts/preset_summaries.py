"""One plain sentence per shipped example: the `summary` the start page's cards show.

The generator scripts (issue6-presets.py, make_composite_presets.py, make_quad_presets.py,
make_spline_presets.py) put it into the scenes they write; hand-written examples carry it in the
file, and composite-cylinder-crease.json's comes from its C++ builder (ClosedFormCreaseTest.cpp,
`cylinderCreasePreset`), which must say the same. `description` keeps the full text with the papers' figures and equations.
"""

SUMMARIES = {
    "composite-column.json": "A six-sided paper column whose edges are curved folds, pushed in and out in turn.",
    "composite-cover-bunny.json": "Eight bendable strips laid side by side over the back of the Stanford bunny.",
    "composite-curved-box.json": "A tray whose bottom meets its long walls along two curved folds.",
    "composite-curved-fold.json": "A square sheet with one curved fold: lift a corner and watch the fold bend.",
    "composite-cylinder-crease.json": "A cylinder folded along a crease that keeps one angle all along; flat, the crease is a catenary.",
    "composite-folded-annulus.json": "A paper ring folded along three circular creases, like a pleated lampshade.",
    "composite-pleated-sheet.json": "A sheet with five wavy folds, lifted at one edge so every fold bends a little.",
    "composite-two-creases.json": "Two curved folds that start at the same point on a sheet's edge.",
    "conical-strip-brim.json": "A hat brim built from cone pieces between a level inner edge and a wavy outer one.",
    "conical-strip-hull.json": "A boat's side panel built from cone pieces between its chine and its sheer line.",
    "conical-strip-twisted.json": "A strongly twisted pair of curves joined by cone pieces.",
    "quad-approx-cgal-box.json": "An open box from CGAL's sample meshes, cut into eight panels that unroll flat.",
    "quad-bend-sheet.json": "A flat sheet bent by its corners without stretching.",
    "quad-cone-deficit.json": "A disc with a wedge cut out and closed up: a cone point.",
    "quad-cone-excess.json": "Two flat pieces glued so that more than a full turn meets at one point: a ruffle.",
    "quad-conformal-flatten.json": "A piece of a sphere flattened so that small shapes keep their angles.",
    "quad-curved-fold.json": "A sheet folded along a curved line by gluing a slit shut.",
    "quad-cut-glue-diagonal.json": "A sheet with a diamond-shaped hole whose edges are glued together.",
    "quad-cut-glue.json": "A sheet with a rectangular hole whose edges are glued together.",
    "quad-cylinder-exact.json": "A piece of a cylinder and its exact flat pattern: nothing to correct.",
    "quad-developable-approx.json": "A saddle-shaped patch made to bend from flat sheet: it gives way by creasing sharply.",
    "quad-dform-convex.json": "A circle and an ellipse of the same perimeter sewn together into a pillow-like D-form.",
    "quad-dform-nonconvex.json": "A peanut shape and a circle of the same perimeter sewn together.",
    "quasi-strip-brim.json": "A hat brim as one smooth bendable strip between a level inner edge and a wavy outer one.",
    "quasi-strip-hull.json": "A boat's side panel as one smooth bendable strip between its chine and its sheer line.",
    "quasi-strip-twisted.json": "A strongly twisted pair of curves joined by one smooth strip, as bendable as they allow.",
    "spline-single-patch.json": "A lumpy smooth surface patch made bendable from flat sheet.",
    "spline-watertight.json": "Four smooth patches sharing their sides, made bendable from flat sheet together.",
    "strip-cone.json": "A strip cut from a cone: bends from flat sheet exactly as it is.",
    "strip-cylinder.json": "A strip cut from a cylinder: bends from flat sheet exactly as it is.",
    "strip-lifted-corner.json": "A flat strip with one corner pulled up.",
    "strip-twisted.json": "A twisted strip that the solver untwists until it bends from flat sheet.",
}


def with_summary(filename, scene):
    """`scene` with its summary placed after `name` (the order a reader expects)."""
    out = {}
    for key, value in scene.items():
        out[key] = value
        if key == "name":
            out["summary"] = SUMMARIES[filename]
    if "summary" not in out:
        out["summary"] = SUMMARIES[filename]
    return out
