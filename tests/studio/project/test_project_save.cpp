// Saving the project model: projectJsonText / loadProjectText round trips for every sample, re-saved
// projects export the same case, saveProject's failures, newProject, and the export progress.
#include "box_body.hpp"
#include "case/case_package.hpp"
#include "project/project.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"
#include "support/scratch_dir.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include <grp.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace viscera;
using ::testing::HasSubstr;
namespace fs = std::filesystem;

namespace {

const fs::path kProjects = fs::path(VISCERA_SOURCE_DIR) / "projects";

std::vector<fs::path> sampleDirs() {
    std::vector<fs::path> dirs;
    for (const fs::directory_entry& e : fs::directory_iterator(kProjects))
        if (e.is_directory() && fs::exists(e.path() / "project.json")) dirs.push_back(e.path());
    std::sort(dirs.begin(), dirs.end());
    return dirs;
}

std::vector<vcase::FileEntry> manifestFiles(const fs::path& casePath) {
    return vcase::CasePackage::open(casePath)->manifest().files;
}

std::string saveError(const studio::Project& p, const fs::path& dir) {
    try {
        studio::saveProject(p, dir);
    } catch (const InputError& e) {
        return e.what();
    }
    return "saved";
}

/// saveError as a user without root's right to write anywhere: as root, in a child process that
/// has become the user nobody.
std::string saveErrorUnprivileged(const studio::Project& p, const fs::path& dir) {
    if (::geteuid() != 0) return saveError(p, dir);
    int fds[2];
    if (::pipe(fds) != 0) return "pipe failed";
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(fds[0]);
        const bool dropped = ::setgroups(0, nullptr) == 0 && ::setgid(65534) == 0 && ::setuid(65534) == 0;
        const std::string m = dropped ? saveError(p, dir) : "cannot become nobody";
        const ssize_t n = ::write(fds[1], m.data(), m.size());
        ::_exit(n == static_cast<ssize_t>(m.size()) ? 0 : 1);
    }
    ::close(fds[1]);
    std::string m;
    char buf[512];
    for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;)
        m.append(buf, static_cast<size_t>(n));
    ::close(fds[0]);
    int status = 0;
    ::waitpid(pid, &status, 0);
    return m;
}

} // namespace

TEST(ProjectSave, EverySampleRoundTripsItsText) {
    const std::vector<fs::path> dirs = sampleDirs();
    ASSERT_EQ(dirs.size(), 5u);
    for (const fs::path& dir : dirs) {
        SCOPED_TRACE(dir.filename().string());
        const studio::Project p = studio::loadProject(dir);
        const std::string text = studio::projectJsonText(p);
        const studio::Project again = studio::loadProjectText(text, dir, "resaved project.json");
        EXPECT_EQ(studio::projectJsonText(again), text);
        // What the texts derive from survives too: the same trajectory and tracks are exported.
        ASSERT_EQ(again.scene.suture.has_value(), p.scene.suture.has_value());
        if (p.scene.suture) {
            EXPECT_EQ(again.scene.suture->trajectoryText, p.scene.suture->trajectoryText);
        }
        ASSERT_EQ(again.scene.interaction.has_value(), p.scene.interaction.has_value());
        if (p.scene.interaction) {
            for (size_t i = 0; i < p.scene.interaction->instruments.size(); ++i)
                EXPECT_EQ(again.scene.interaction->instruments[i].trackText,
                          p.scene.interaction->instruments[i].trackText);
        }
        // The folder given with a trailing '/' writes the same relative paths.
        EXPECT_EQ(studio::projectJsonText(studio::loadProject(dir.string() + "/")), text);
    }
}

TEST(ProjectSave, KeepsTheTrajectorySpecAndTheFilesRelative) {
    const studio::Project a = studio::loadProject(kProjects / "anastomosis");
    ASSERT_TRUE(a.trajectory.generator.has_value());
    EXPECT_EQ(a.trajectory.generator->stitches, 13);
    EXPECT_EQ(a.trajectory.generator->pullPerSegment, 0.0021);
    EXPECT_THAT(studio::projectJsonText(a), HasSubstr("\"generator\": \"anastomosis\""));
    const studio::Project rectum = studio::loadProject(kProjects / "rectum");
    ASSERT_EQ(rectum.trackFiles.size(), 3u);
    EXPECT_EQ(rectum.trackFiles[0], kProjects / "rectum" / "tools" / "grasper.track");
    EXPECT_EQ(rectum.scene.interaction->instruments[0].trackPath, "tools/grasper.track"); // in the case
    const std::string rectumText = studio::projectJsonText(rectum);
    EXPECT_THAT(rectumText, HasSubstr("\"track\": \"tools/grasper.track\""));
    EXPECT_THAT(rectumText, HasSubstr("\"track\": \"tools/clipper.track\""));

    // A trajectory file and a mesh file, in a sub-folder, come back as the same relative paths.
    test::Scratch scratch("viscera-save");
    studio::Project p = a;
    p.dir = scratch.dir;
    fs::create_directories(scratch.dir / "data");
    writeFileAtomic(scratch.dir / "data" / "needle.traj", a.scene.suture->trajectoryText);
    p.trajectory = {std::nullopt, scratch.dir / "data" / "needle.traj"};
    const std::string text = studio::projectJsonText(p);
    EXPECT_THAT(text, HasSubstr("\"file\": \"data/needle.traj\""));
    const studio::Project back = studio::loadProjectText(text, scratch.dir, "p.json");
    EXPECT_FALSE(back.trajectory.generator);
    EXPECT_EQ(back.trajectory.file, scratch.dir / "data" / "needle.traj");
    EXPECT_EQ(back.scene.suture->trajectoryText, a.scene.suture->trajectoryText);
    EXPECT_EQ(studio::projectJsonText(back), text);

    // A file outside the project folder cannot be written relative to it: nothing is saved.
    p.trajectory.file = "/elsewhere/needle.traj";
    EXPECT_THAT(saveError(p, scratch.dir), HasSubstr("project.json: suture.trajectory.file: '/elsewhere/needle.traj' "
                                                     "is not inside the project folder"));
    EXPECT_FALSE(fs::exists(scratch.dir / "project.json"));
}

TEST(ProjectSave, ResavedSamplesExportTheSameCase) {
    // The two cheap samples, and the ones with track files, paint, a surface and a suture generator.
    for (const char* name : {"tissue-slab", "organ-blob", "rectum", "anastomosis"}) {
        SCOPED_TRACE(name);
        test::Scratch scratch("viscera-resave");
        const fs::path copy = scratch.dir / name;
        fs::copy(kProjects / name, copy, fs::copy_options::recursive);
        studio::saveProject(studio::loadProject(copy), copy);
        EXPECT_NE(readFile(copy / "project.json"), readFile(kProjects / name / "project.json"))
            << "the saved text is the writer's, not a copy";
        const fs::path original = scratch.dir / "original.vcase", resaved = scratch.dir / "resaved.vcase";
        studio::exportCase(studio::loadProject(kProjects / name), original);
        studio::exportCase(studio::loadProject(copy), resaved);
        const std::vector<vcase::FileEntry> files = manifestFiles(original);
        EXPECT_FALSE(files.empty());
        EXPECT_EQ(manifestFiles(resaved), files);
        for (const fs::directory_entry& e : fs::directory_iterator(copy))
            EXPECT_NE(e.path().filename().string()[0], '.') << "a temporary file is left: " << e.path();
    }
}

TEST(ProjectSave, RefusesAFolderItCannotWriteAndLeavesNothing) {
    test::Scratch scratch("viscera-save-ro");
    const fs::path ro = scratch.dir / "ro";
    fs::create_directories(ro);
    const studio::Project p = studio::newProject(ro, "ro-case");
    ASSERT_EQ(::chmod(ro.c_str(), 0555), 0);
    EXPECT_EQ(saveErrorUnprivileged(p, ro),
              (ro / "project.json").string() + ": cannot save: the folder is not writable (Permission denied)");
    ::chmod(ro.c_str(), 0755);
    EXPECT_TRUE(fs::is_empty(ro));

    EXPECT_EQ(saveError(p, scratch.dir / "missing"), (scratch.dir / "missing" / "project.json").string() +
                                                         ": cannot save: the folder '" +
                                                         (scratch.dir / "missing").string() + "' does not exist");
    EXPECT_FALSE(fs::exists(scratch.dir / "missing"));
    writeFileAtomic(scratch.dir / "file", "x");
    EXPECT_THAT(saveError(p, scratch.dir / "file"), HasSubstr("' is not a folder"));
}

TEST(ProjectSave, NewProjectExportsAndSaves) {
    test::Scratch scratch("viscera-new");
    studio::Project p = studio::newProject(scratch.dir, "new-case");
    EXPECT_TRUE(p.bodies.empty()) << "File → New starts without a placeholder body";
    // the slab the studio once added, by hand: a body is all a new project needs to export
    p.bodies.push_back(test::boxBody(sim::Vec3(0.1, 0.02, 0.04), {20, 4, 8}));
    studio::ExportResult r = studio::exportCase(p, scratch.dir / "new.vcase");
    EXPECT_EQ(r.features, (std::vector<std::string>{"gravity", "xpbd"}));
    ASSERT_EQ(r.bodies.size(), 1u);
    EXPECT_EQ(r.bodies[0].name, "tissue");
    EXPECT_EQ(r.bodies[0].tets, 20u * 4 * 8 * 6);
    EXPECT_EQ(r.bodies[0].fixedNodes, 5u * 9);
    EXPECT_NEAR(r.bodies[0].quality.totalVolume, 0.1 * 0.02 * 0.04, 1e-12);

    studio::saveProject(p, scratch.dir);
    EXPECT_EQ(studio::projectJsonText(studio::loadProject(scratch.dir)), studio::projectJsonText(p));
    try {
        studio::newProject(scratch.dir, "Bad Id");
        FAIL() << "accepted";
    } catch (const InputError& e) {
        EXPECT_THAT(e.what(), HasSubstr("project.json: caseId:"));
    }
}

TEST(ProjectSave, ExportReportsNumberedStages) {
    std::vector<std::string> lines;
    test::Scratch scratch("viscera-stages");
    studio::exportCase(studio::loadProject(kProjects / "tissue-slab"), scratch.dir / "slab.vcase",
                       [&](size_t index, size_t total, const std::string& stage) {
                           lines.push_back(std::to_string(index) + "/" + std::to_string(total) + " " + stage);
                       });
    EXPECT_EQ(lines, (std::vector<std::string>{"1/3 meshing body 'slab'", "2/3 checking the scene", "3/3 packaging"}));
}
