#include "zip_craft.hpp"

#include "case/sha256.hpp"
#include "sim/util/atomic_file.hpp"
#include "sim/util/error.hpp"

#include <zip.h>

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <unistd.h>

namespace viscera::vcase::test {

std::string craftZip(const std::vector<RawEntry>& entries) {
    zip_error_t error;
    zip_error_init(&error);
    zip_source_t* out = zip_source_buffer_create(nullptr, 0, 0, &error);
    if (!out) throw std::runtime_error("craftZip: zip_source_buffer_create failed");
    zip_source_keep(out);
    zip_t* za = zip_open_from_source(out, ZIP_TRUNCATE, &error);
    if (!za) throw std::runtime_error("craftZip: zip_open_from_source failed");
    for (const RawEntry& e : entries) {
        zip_source_t* src = zip_source_buffer(za, e.bytes.data(), e.bytes.size(), 0);
        zip_int64_t index = src ? zip_file_add(za, e.name.c_str(), src, ZIP_FL_ENC_RAW) : -1;
        if (index < 0) throw std::runtime_error("craftZip: cannot add " + e.name + ": " + zip_strerror(za));
        auto i = static_cast<zip_uint64_t>(index);
        int32_t method = e.method != RawEntry::kByFlag ? e.method : (e.deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE);
        uint32_t mode = e.unixMode.value_or(0100644);
        if (zip_set_file_compression(za, i, method, 0) != 0 ||
            zip_file_set_external_attributes(za, i, 0, ZIP_OPSYS_UNIX, mode << 16) != 0)
            throw std::runtime_error("craftZip: cannot set attributes of " + e.name);
    }
    if (zip_close(za) != 0) throw std::runtime_error(std::string("craftZip: ") + zip_strerror(za));
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_source_stat(out, &st) != 0 || zip_source_open(out) != 0)
        throw std::runtime_error("craftZip: cannot read the archive back");
    std::string bytes(st.size, '\0');
    zip_int64_t n = zip_source_read(out, bytes.data(), st.size);
    zip_source_close(out);
    zip_source_free(out);
    zip_error_fini(&error);
    if (n != static_cast<zip_int64_t>(st.size)) throw std::runtime_error("craftZip: short read");
    return bytes;
}

Manifest manifestFor(const std::vector<RawEntry>& files) {
    Manifest m;
    m.caseId = "test-case";
    m.caseVersion = "1.0.0";
    m.minPlayerVersion = "0.1.0";
    m.title = "Test case";
    m.features = {"xpbd", "gravity"};
    for (const RawEntry& f : files)
        m.files.push_back({f.name, f.bytes.size(), sha256Hex(f.bytes)});
    return m;
}

std::string craftPackage(const Manifest& manifest, const std::vector<RawEntry>& files) {
    std::vector<RawEntry> all{{std::string(kManifestName), manifest.toJsonText()}};
    all.insert(all.end(), files.begin(), files.end());
    return craftZip(all);
}

std::string unitTetVtet() {
    return "vtet 1\n"
           "vertices 4\n"
           "0 0 0\n"
           "1 0 0\n"
           "0 1 0\n"
           "0 0 1\n"
           "tets 1\n"
           "0 1 2 3\n";
}

size_t patchBytes(std::string& bytes, const std::string& from, const std::string& to) {
    if (from.size() != to.size()) throw std::invalid_argument("patchBytes: lengths differ");
    size_t count = 0;
    for (size_t at = bytes.find(from); at != std::string::npos; at = bytes.find(from, at + 1)) {
        bytes.replace(at, to.size(), to);
        ++count;
    }
    return count;
}

std::string messageOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

ScratchDir::ScratchDir() {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "viscera_case_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) +
                       (info ? std::string("_") + info->name() : "");
    m_path = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(m_path);
    std::filesystem::create_directories(m_path);
}

ScratchDir::~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(m_path, ec);
}

std::filesystem::path ScratchDir::write(const std::string& name, const std::string& bytes) const {
    std::filesystem::path p = m_path / name;
    writeFileAtomic(p, bytes);
    return p;
}

} // namespace viscera::vcase::test
