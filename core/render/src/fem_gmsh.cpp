// Everything that talks to gmsh (fss/render/fem_io.h): MSH 4.1 / 2.2 and UNV written through gmsh's C++ API
// from discrete entities (one surface per group, one curve for the feature edges) and their physical groups;
// MSH read back the same way. gmsh keeps global state and is not thread-safe: every use holds one lock
// and initializes / finalizes gmsh around itself (GmshScope).
#include "fem_detail.h"

#include "fss/face_groups.h"

#include <gmsh.h>

#include <map>
#include <mutex>
#include <stdexcept>

namespace fs = std::filesystem;

namespace fss::render::detail {
namespace {

std::mutex& gmshMutex() {
    static std::mutex m;
    return m;
}

/// One use of gmsh: the process-wide lock, gmsh initialized quietly (no configuration files, no terminal
/// output) and finalized again.
class GmshScope {
public:
    GmshScope() : lock_(gmshMutex()) {
        gmsh::initialize(0, nullptr, false);
        gmsh::option::setNumber("General.Terminal", 0);
        gmsh::option::setNumber("General.Verbosity", 1);
    }
    ~GmshScope() { gmsh::finalize(); }
    GmshScope(const GmshScope&) = delete;
    GmshScope& operator=(const GmshScope&) = delete;

    static std::string lastError() {
        std::string e;
        try {
            gmsh::logger::getLastError(e);
        } catch (...) {
        }
        return e.empty() ? std::string("gmsh reported an error") : "gmsh: " + e;
    }

private:
    std::lock_guard<std::mutex> lock_;
};

} // namespace

void writeGmsh(const FemMesh& m, const fs::path& path, const FemWriteOptions& options) {
    for (const std::string& name : m.groupNames)
        if (name.find('"') != std::string::npos)
            failWrite(path, "gmsh cannot hold the group name '" + name + "' (it contains '\"')");
    TempFile temp(path);
    {
        GmshScope gmshScope;
        try {
            gmsh::model::add("fss");
            const int groups = int(m.groupNames.size());
            for (int g = 1; g <= groups; ++g)
                gmsh::model::addDiscreteEntity(2, g);
            // Every node is classified on the first surface (a discrete model needs no finer classification).
            std::vector<std::size_t> nodeTags(m.nodes.size());
            std::vector<double> coords;
            coords.reserve(3 * m.nodes.size());
            for (std::size_t i = 0; i < m.nodes.size(); ++i) {
                nodeTags[i] = i + 1;
                coords.insert(coords.end(), m.nodes[i].begin(), m.nodes[i].end());
            }
            gmsh::model::mesh::addNodes(2, 1, nodeTags, coords);
            std::vector<std::vector<std::size_t>> tags(static_cast<std::size_t>(groups)),
                nodes(static_cast<std::size_t>(groups));
            for (std::size_t t = 0; t < m.triangles.size(); ++t) {
                const auto g = std::size_t(m.group[t]);
                tags[g].push_back(t + 1);
                for (std::size_t n : m.triangles[t])
                    nodes[g].push_back(n + 1);
            }
            for (int g = 1; g <= groups; ++g) {
                gmsh::model::mesh::addElementsByType(g, 2, tags[std::size_t(g - 1)],
                                                     nodes[std::size_t(g - 1)]);
                gmsh::model::addPhysicalGroup(2, {g}, g);
                gmsh::model::setPhysicalName(2, g, m.groupNames[std::size_t(g - 1)]);
            }
            if (!m.edges.empty()) {
                gmsh::model::addDiscreteEntity(1, 1);
                std::vector<std::size_t> edgeTags, edgeNodes;
                for (std::size_t e = 0; e < m.edges.size(); ++e) {
                    edgeTags.push_back(m.triangles.size() + e + 1);
                    edgeNodes.push_back(m.edges[e][0] + 1);
                    edgeNodes.push_back(m.edges[e][1] + 1);
                }
                gmsh::model::mesh::addElementsByType(1, 1, edgeTags, edgeNodes);
                gmsh::model::addPhysicalGroup(1, {1}, groups + 1);
                gmsh::model::setPhysicalName(1, groups + 1, m.edgeGroup);
            }
            gmsh::option::setNumber("Mesh.MshFileVersion", options.mshVersion);
            gmsh::option::setNumber("Mesh.Binary", 0);
            gmsh::option::setNumber("Mesh.SaveAll", 0);
            gmsh::write(temp.path().string());
        } catch (...) {
            failWrite(path, GmshScope::lastError());
        }
    }
    temp.commit();
}

PolygonSoup readGmsh(const fs::path& path) {
    PolygonSoup soup;
    std::string problem;
    {
        GmshScope gmshScope;
        try {
            gmsh::open(path.string());
            std::vector<std::size_t> nodeTags;
            std::vector<double> coords, parametric;
            gmsh::model::mesh::getNodes(nodeTags, coords, parametric, -1, -1, false, false);
            std::map<std::size_t, std::size_t> index;
            for (std::size_t i = 0; i < nodeTags.size(); ++i) {
                index[nodeTags[i]] = i;
                soup.points.emplace_back(coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]);
            }
            std::map<int, std::int32_t> groupOfPhysical;
            gmsh::vectorpair surfaces;
            gmsh::model::getEntities(surfaces, 2);
            for (const auto& [dim, tag] : surfaces) {
                std::vector<int> physicals;
                gmsh::model::getPhysicalGroupsForEntity(dim, tag, physicals);
                if (physicals.size() > 1) {
                    problem = "its surface " + std::to_string(tag) + " belongs to " +
                              std::to_string(physicals.size()) +
                              " physical groups, but FSS holds one group per face";
                    break;
                }
                std::int32_t group = kNoGroup;
                if (!physicals.empty()) {
                    const auto found = groupOfPhysical.find(physicals[0]);
                    if (found != groupOfPhysical.end()) {
                        group = found->second;
                    } else {
                        std::string name;
                        gmsh::model::getPhysicalName(2, physicals[0], name);
                        if (name.empty()) name = "physical_" + std::to_string(physicals[0]);
                        group = std::int32_t(soup.groupNames.size());
                        soup.groupNames.push_back(name);
                        groupOfPhysical[physicals[0]] = group;
                    }
                }
                std::vector<int> types;
                std::vector<std::vector<std::size_t>> elementTags, elementNodes;
                gmsh::model::mesh::getElements(types, elementTags, elementNodes, dim, tag);
                for (std::size_t k = 0; k < types.size() && problem.empty(); ++k) {
                    const std::size_t corners = types[k] == 2 ? 3 : types[k] == 3 ? 4 : 0;
                    if (corners == 0) {
                        problem = "its surface " + std::to_string(tag) + " has elements of gmsh type " +
                                  std::to_string(types[k]) +
                                  ", but FSS reads linear triangles and quadrangles only";
                        break;
                    }
                    for (std::size_t e = 0; e + corners <= elementNodes[k].size(); e += corners) {
                        std::vector<std::size_t> poly;
                        for (std::size_t c = 0; c < corners; ++c)
                            poly.push_back(index.at(elementNodes[k][e + c]));
                        soup.polygons.push_back(std::move(poly));
                        soup.groups.push_back(group);
                    }
                }
                if (!problem.empty()) break;
            }
        } catch (const std::out_of_range&) {
            problem = "an element uses a node the file does not define";
        } catch (...) {
            problem = GmshScope::lastError();
        }
    }
    if (!problem.empty()) failRead(path, problem);
    if (soup.polygons.empty()) failRead(path, "it holds no surface elements (triangles or quadrangles)");
    if (soup.groupNames.empty()) soup.groups.clear();
    return soup;
}

} // namespace fss::render::detail
