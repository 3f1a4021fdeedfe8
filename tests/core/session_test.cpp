// Session: scan → preview → accept, undo and redo restore the exact meshes.
#include "fss/error.h"
#include "fss/session.h"
#include "fss/shapes.h"

#include <gtest/gtest.h>

#include <sstream>

namespace {

// The mesh written as text in index order (points bit-exact via hexfloat): equal strings = equal meshes.
std::string fingerprint(const fss::Mesh& mesh) {
    std::ostringstream out;
    out << std::hexfloat;
    for (auto v : mesh.vertices()) out << mesh.point(v) << '\n';
    for (auto f : mesh.faces()) {
        for (auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) out << std::size_t(v) << ' ';
        out << '\n';
    }
    return out.str();
}

fss::ScanStep isoStep(const fss::Mesh& mesh, int resolution) {
    fss::ScanStep step;
    step.params.camera = fss::Camera::standardView(fss::StandardView::Iso, fss::boundingBox(mesh), resolution,
                                                   resolution);
    return step;
}

TEST(Session, AcceptUndoRedoAreExact) {
    fss::Session session(fss::shapes::icosphere(3));
    const std::string original = fingerprint(session.current());
    EXPECT_FALSE(session.canUndo());
    EXPECT_THROW(session.accept(), fss::InvalidInputError);
    session.scan(isoStep(session.reference(), 64));
    ASSERT_NE(session.preview(), nullptr);
    EXPECT_GT(session.preview()->patch.mesh.number_of_faces(), 100u);
    EXPECT_EQ(fingerprint(session.current()), original); // a preview changes nothing
    const fss::StitchReport& report = session.accept();
    EXPECT_GT(report.facesAdded, 0u);
    EXPECT_EQ(session.preview(), nullptr);
    const std::string once = fingerprint(session.current());
    EXPECT_NE(once, original);
    session.undo();
    EXPECT_EQ(fingerprint(session.current()), original);
    EXPECT_TRUE(session.canRedo());
    session.redo();
    EXPECT_EQ(fingerprint(session.current()), once);
    EXPECT_THROW(session.redo(), fss::InvalidInputError);
    ASSERT_EQ(session.events().size(), 3u);
    EXPECT_EQ(session.events()[1].kind, fss::SessionEvent::Kind::Undo);
}

TEST(Session, RejectsEmptyMesh) {
    EXPECT_THROW(fss::Session(fss::Mesh{}), fss::InvalidInputError);
}

} // namespace
