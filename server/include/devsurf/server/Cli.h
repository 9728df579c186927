#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace devsurf::server {

/// Entry point of the `devsurf` executable: dispatches subcommands.
/// Exit codes: 0 success, 1 runtime failure (I/O, solver), 2 bad input or usage.
int runCli(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
           std::ostream& err);

/// `devsurf solve SCENE [--iterations N] [--out REPORT.json] [--export FORMAT:FILE]…`
/// SCENE may be "-" for standard input. The report goes to stdout unless --out is given.
int solveCommand(const std::vector<std::string>& args, std::istream& in, std::ostream& out,
                 std::ostream& err);

/// `devsurf reference SHAPE [--thin RADIUS] [--seed N] [--out CLOUD.xyz]`: what a reference
/// shape holds, as JSON; thinned with a fitted normal per kept point when asked (issue 15).
int referenceCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `devsurf fit SHAPE [--centre X,Y,Z --radius R] [--thin RADIUS] …`: a strip scene that
/// approximates a region of a reference shape (000_… §4.2, issue 15): the region thinned with a
/// normal per point, a strip placed by PCA over it, eq. (9)–(11) as its approximation target.
int fitCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `devsurf merge FIRST.json SECOND.json [--out SCENE.json]`: two strip scenes merged into one
/// by joining their control-point sequences (000_… Fig. 10c; models::strip::mergeStrips).
int mergeCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `devsurf cover SHAPE [--centre X,Y,Z --radius R] [--strips K] …`: a region covered by strips
/// side by side whose paired boundaries become the shared edges of one composite scene (000_…
/// Fig. 10d–e; models::strip::coverRegion, models::composite::compositeFromStrips).
int coverCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);
/// `devsurf approximate MESH …`: a segmented triangle mesh → a quad_mesh scene of glued developable
/// patches with proximity to the mesh (004_… §5, Fig. 20–21). Exit 0, 2 on bad arguments or input, 1
/// otherwise.
int approximateCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `devsurf serve …`: the daemon, until SIGINT/SIGTERM.
int serveCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `devsurf worker --store postgresql://… [--job-workers N] …`: solves jobs from a shared store's
/// queue (issue 18; docs/scaling.md) without serving HTTP, until SIGINT/SIGTERM.
int workerCommand(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

/// `devsurf job submit SCENE --server URL [--wait [--require-quality]] …` (SCENE "-": `in`).
int jobCommand(const std::vector<std::string>& args, std::istream& in, std::ostream& out, std::ostream& err);

}  // namespace devsurf::server
