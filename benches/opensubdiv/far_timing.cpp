// Times OpenSubdiv 3.6 Far (CPU, one thread) on the quad torus of
// `subdyn bench subdivide`, stage by stage, so the two can be compared in the
// same run (benches/compare/subdivide_vs_opensubdiv.py).
//
// The mesh is subdyn::examples::torus(N, N, 1.0, 0.3): N*N vertices, vertex
// (i, j) at index i*N + j, position ((R + r cos b) cos a, (R + r cos b) sin a,
// r sin b) with a = 2 pi i / N, b = 2 pi j / N, and the quad of (i, j) is
// (i, j), (i+1, j), (i+1, j+1), (i, j+1) (indices mod N). Building these
// arrays is not timed (subdyn builds its PolyMesh before its timer starts).
//
// Stages (std::chrono::steady_clock):
//   topology        Far::TopologyRefinerFactory<TopologyDescriptor>::Create
//   refinement      TopologyRefiner::RefineUniform(L)
//   stencil build   StencilTableFactoryReal<REAL>::Create, last level only,
//                   factorized in terms of the control points
//   apply           StencilTableReal<REAL>::UpdateValues from the control
//                   points (double xyz) into the level-L points, best of R
//
// Usage: far_timing [--grid N] [--levels L] [--repeat R] [--real float|double]
//                   [--full-topology 0|1] [--write-control OBJ]
//                   [--write-refined OBJ]
// The last stdout line is one JSON object.
//
// Uses only OpenSubdiv's public API.

#include <opensubdiv/far/stencilTable.h>
#include <opensubdiv/far/stencilTableFactory.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefiner.h>
#include <opensubdiv/far/topologyRefinerFactory.h>
#include <opensubdiv/version.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

using namespace OpenSubdiv;

#define FT_STR2(x) #x
#define FT_STR(x) FT_STR2(x)
#define FT_OSD_VERSION                                                     \
    FT_STR(OPENSUBDIV_VERSION_MAJOR) "." FT_STR(OPENSUBDIV_VERSION_MINOR) "." \
        FT_STR(OPENSUBDIV_VERSION_PATCH)

namespace {

// A position with the two members UpdateValues needs; weights arrive as REAL
// (float or double) and the sums are accumulated in double.
struct Point {
    double x, y, z;
    void Clear(void * = nullptr) { x = y = z = 0.0; }
    void AddWithWeight(Point const &p, double w) {
        x += w * p.x;
        y += w * p.y;
        z += w * p.z;
    }
};

struct Args {
    int grid = 316;
    int levels = 2;
    int repeat = 5;
    bool use_double = false;
    bool full_topology = true;
    std::string write_control;
    std::string write_refined;
};

[[noreturn]] void usage(char const *msg) {
    std::fprintf(stderr,
                 "far_timing: %s\n"
                 "usage: far_timing [--grid N] [--levels L] [--repeat R] [--real float|double]\n"
                 "                  [--full-topology 0|1] [--write-control OBJ] [--write-refined OBJ]\n",
                 msg);
    std::exit(2);
}

int parse_int(char const *name, char const *value, int lo, int hi) {
    char *end = nullptr;
    long v = std::strtol(value, &end, 10);
    if (end == value || *end != '\0' || v < lo || v > hi) {
        std::string m = std::string(name) + " " + value + ": expected an integer from " +
                        std::to_string(lo) + " to " + std::to_string(hi);
        usage(m.c_str());
    }
    return static_cast<int>(v);
}

Args parse(int argc, char **argv) {
    Args a;
    for (int k = 1; k < argc; ++k) {
        std::string opt = argv[k];
        if (opt == "-h" || opt == "--help") {
            usage("times OpenSubdiv Far on the N x N quad torus of `subdyn bench subdivide`");
        }
        if (k + 1 >= argc) usage((opt + " needs a value").c_str());
        char const *v = argv[++k];
        if (opt == "--grid") {
            a.grid = parse_int("--grid", v, 3, 100000);
        } else if (opt == "--levels") {
            a.levels = parse_int("--levels", v, 1, 8);
        } else if (opt == "--repeat") {
            a.repeat = parse_int("--repeat", v, 1, 1000000);
        } else if (opt == "--real") {
            if (std::strcmp(v, "float") == 0) {
                a.use_double = false;
            } else if (std::strcmp(v, "double") == 0) {
                a.use_double = true;
            } else {
                usage("--real: expected float or double");
            }
        } else if (opt == "--full-topology") {
            a.full_topology = parse_int("--full-topology", v, 0, 1) == 1;
        } else if (opt == "--write-control") {
            a.write_control = v;
        } else if (opt == "--write-refined") {
            a.write_refined = v;
        } else {
            usage(("unknown option " + opt).c_str());
        }
    }
    return a;
}

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The torus of subdyn::examples::torus(n, n, 1.0, 0.3).
struct Torus {
    std::vector<Point> positions;
    std::vector<int> verts_per_face;
    std::vector<int> face_verts;
};

Torus make_torus(int n) {
    double const tau = 6.283185307179586;  // f64::consts::TAU
    double const r_major = 1.0, r_minor = 0.3;
    Torus t;
    t.positions.reserve(static_cast<size_t>(n) * n);
    for (int i = 0; i < n; ++i) {
        double a = tau * static_cast<double>(i) / static_cast<double>(n);
        for (int j = 0; j < n; ++j) {
            double b = tau * static_cast<double>(j) / static_cast<double>(n);
            double r = r_major + r_minor * std::cos(b);
            t.positions.push_back(Point{r * std::cos(a), r * std::sin(a), r_minor * std::sin(b)});
        }
    }
    auto id = [n](int i, int j) { return (i % n) * n + (j % n); };
    t.verts_per_face.assign(static_cast<size_t>(n) * n, 4);
    t.face_verts.reserve(4 * static_cast<size_t>(n) * n);
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            int q[4] = {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)};
            t.face_verts.insert(t.face_verts.end(), q, q + 4);
        }
    }
    return t;
}

Far::TopologyRefiner *create_refiner(Torus const &t) {
    Far::TopologyDescriptor desc;
    desc.numVertices = static_cast<int>(t.positions.size());
    desc.numFaces = static_cast<int>(t.verts_per_face.size());
    desc.numVertsPerFace = t.verts_per_face.data();
    desc.vertIndicesPerFace = t.face_verts.data();

    Sdc::Options sdc;
    // The torus is closed, so the boundary rule has no effect; edge-only is
    // subdyn's default (no corner sharpening).
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    return Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc));
}

Far::TopologyRefiner::UniformOptions uniform_options(int levels, bool full_topology) {
    Far::TopologyRefiner::UniformOptions o(levels);
    // subdyn numbers child vertices face points, then edge points, then
    // vertex points; Far does the same with this option (its edges are
    // numbered differently, so edge points come in another order: the
    // level-L points are the same set, not the same array).
    o.orderVerticesFromFacesFirst = true;
    o.fullTopologyInLastLevel = full_topology;
    return o;
}

bool write_obj(std::string const &path, std::vector<Point> const &p, Torus const *faces) {
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) return false;
    for (auto const &q : p) std::fprintf(f, "v %.17g %.17g %.17g\n", q.x, q.y, q.z);
    if (faces) {
        for (size_t k = 0; k < faces->face_verts.size(); k += 4) {
            std::fprintf(f, "f %d %d %d %d\n", faces->face_verts[k] + 1, faces->face_verts[k + 1] + 1,
                         faces->face_verts[k + 2] + 1, faces->face_verts[k + 3] + 1);
        }
    }
    return std::fclose(f) == 0;
}

template <typename REAL>
int run(Args const &args) {
    Torus const torus = make_torus(args.grid);

    // (a) level-0 topology
    auto t0 = Clock::now();
    std::unique_ptr<Far::TopologyRefiner> refiner(create_refiner(torus));
    double const topology_s = seconds_since(t0);
    if (!refiner) {
        std::fprintf(stderr, "far_timing: TopologyRefinerFactory::Create failed\n");
        return 1;
    }

    // (b) uniform refinement
    t0 = Clock::now();
    refiner->RefineUniform(uniform_options(args.levels, args.full_topology));
    double const refinement_s = seconds_since(t0);

    // (c) stencils of the last level in terms of the control points
    typename Far::StencilTableFactoryReal<REAL>::Options so;
    so.interpolationMode = Far::StencilTableFactoryReal<REAL>::INTERPOLATE_VERTEX;
    so.generateOffsets = false;
    so.generateControlVerts = false;
    so.generateIntermediateLevels = false;
    so.factorizeIntermediateLevels = true;
    so.maxLevel = static_cast<unsigned>(args.levels);
    t0 = Clock::now();
    std::unique_ptr<Far::StencilTableReal<REAL> const> table(
        Far::StencilTableFactoryReal<REAL>::Create(*refiner, so));
    double const stencil_build_s = seconds_since(t0);

    int const stencils = table->GetNumStencils();
    size_t const entries = table->GetControlIndices().size();
    int const last_vertices = refiner->GetLevel(args.levels).GetNumVertices();
    int const last_faces = refiner->GetLevel(args.levels).GetNumFaces();

    // (d) application, best of --repeat
    std::vector<Point> refined(static_cast<size_t>(stencils));
    double apply_s = std::numeric_limits<double>::infinity();
    for (int k = 0; k < args.repeat; ++k) {
        t0 = Clock::now();
        table->UpdateValues(torus.positions.data(), refined.data());
        apply_s = std::min(apply_s, seconds_since(t0));
    }
    double checksum = 0.0;  // sum of |p|^2: keeps the applications observable
    for (auto const &p : refined) checksum += p.x * p.x + p.y * p.y + p.z * p.z;

    // For comparison only: the refinement Far needs for stencils alone
    // (fullTopologyInLastLevel = false), on a fresh refiner.
    std::unique_ptr<Far::TopologyRefiner> minimal(create_refiner(torus));
    t0 = Clock::now();
    minimal->RefineUniform(uniform_options(args.levels, false));
    double const refinement_minimal_s = seconds_since(t0);
    minimal.reset();

    if (!args.write_control.empty() && !write_obj(args.write_control, torus.positions, &torus)) {
        std::fprintf(stderr, "far_timing: cannot write %s\n", args.write_control.c_str());
        return 1;
    }
    if (!args.write_refined.empty() && !write_obj(args.write_refined, refined, nullptr)) {
        std::fprintf(stderr, "far_timing: cannot write %s\n", args.write_refined.c_str());
        return 1;
    }

    char const *real = sizeof(REAL) == sizeof(double) ? "double" : "float";
    double const setup_s = topology_s + refinement_s + stencil_build_s;
    std::printf("OpenSubdiv %s Far: %dx%d quad torus, %d level(s) -> %d vertices, %d faces\n",
                FT_OSD_VERSION, args.grid, args.grid, args.levels, last_vertices,
                last_faces);
    std::printf("stencil table (%s weights): %d stencils, %zu entries; 1 thread; apply = best of %d\n",
                real, stencils, entries, args.repeat);
    std::printf(
        "{\"topology_s\":%.9g,\"refinement_s\":%.9g,\"stencil_build_s\":%.9g,\"setup_s\":%.9g,"
        "\"apply_s\":%.9g,\"stencils\":%d,\"entries\":%zu,\"grid\":%d,\"levels\":%d,"
        "\"repeat\":%d,\"real\":\"%s\",\"full_topology_in_last_level\":%s,"
        "\"refinement_minimal_s\":%.9g,\"vertices\":%d,\"faces\":%d,"
        "\"opensubdiv\":\"%s\",\"checksum\":%.17g}\n",
        topology_s, refinement_s, stencil_build_s, setup_s, apply_s, stencils, entries, args.grid,
        args.levels, args.repeat, real, args.full_topology ? "true" : "false",
        refinement_minimal_s, last_vertices, last_faces, FT_OSD_VERSION, checksum);
    return 0;
}

}  // namespace

int main(int argc, char **argv) {
    Args const args = parse(argc, argv);
    return args.use_double ? run<double>(args) : run<float>(args);
}
