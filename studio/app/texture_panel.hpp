#pragma once
/// The "Material maps" panel [A §6.2, issue 17]: the selected body's or surface's texture block
/// (spec file, tiles per metre, normal strength) as editable fields, live thumbnails of the
/// spec's diffuse, roughness and normal maps and its palette, and a palette picker on a photo.
///
/// Apply and Remove are Document edits (one undo step each), checked by the project reader's
/// rules (a spec outside the project folder is refused with its one-line message) and by the
/// spec reader (a spec that does not parse is refused too). The thumbnails and the picked
/// palette are made off the UI thread (QtConcurrent); a request made while one runs supersedes
/// it, whose result is then dropped. The spec file is only read: the seed field previews other
/// seeds without writing it.
#include "bake/texture.hpp"
#include "project/project.hpp"

#include <QImage>
#include <QString>
#include <QWidget>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

class QComboBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QSpinBox;
class QGridLayout;

namespace viscera::studio {

class Document;

/// The preview of one texture spec at a reduced size.
struct TextureThumbnails {
    QImage diffuse, roughness, normal; ///< null when the spec does not write that map
    std::vector<bake::Rgb8> colors;    ///< the palette the maps use (explicit or extracted)
    std::vector<double> shares;        ///< share of each colour when extracted, else empty
    int size = 0;                      ///< side of the thumbnails, pixels
    uint64_t seed = 0;                 ///< the seed they were made with
};

/// Loads the spec file, optionally replaces its seed, caps its size at `maxSide` pixels (a power
/// of two, [8, 4096]; quadtree levels finer than the smaller image are dropped, the height blur
/// is scaled with the size) and generates and encodes its diffuse, roughness and normal maps
/// (8 bits) with bake::generateTextureSet / encodeTextureSet. Throws viscera::InputError naming
/// the spec, std::invalid_argument for a bad maxSide. Cost: one texture generation at maxSide².
TextureThumbnails makeTextureThumbnails(const std::filesystem::path& specFile, std::optional<uint64_t> seed,
                                        int maxSide);

/// The palette of a photo file (bake::readRgb8Image, at most 2048 pixels a side, then
/// bake::extractPalette with `params`). Throws viscera::InputError naming the file.
std::vector<bake::PaletteColor> pickPalette(const std::filesystem::path& image, const bake::PaletteParams& params);

class TexturePanel : public QWidget {
    Q_OBJECT
public:
    enum class Target { None, Body, Surface };
    static constexpr int kThumbnailSide = 256; ///< thumbnails cap the spec's size at this

    explicit TexturePanel(Document* doc, QWidget* parent = nullptr);
    ~TexturePanel() override;

    /// The body or surface whose texture block is shown (Target::None or an index out of range:
    /// nothing is selected, the fields are disabled).
    void setTarget(Target kind, int index);
    Target targetKind() const { return m_kind; }
    int targetIndex() const { return m_index; }

    /// Writes the fields into the selection's texture block (creating it). Returns the refusal
    /// (empty when applied), also shown in the status line.
    QString applyFields();
    /// Removes the selection's texture block. Returns the refusal (empty when applied).
    QString removeTexture();
    /// Extracts the palette of `file` off the UI thread with the method of the combo box; the
    /// swatches appear when done (palettePending() false).
    void pickPaletteFrom(const QString& file);
    /// Starts a new thumbnail generation of the spec field's file with the seed field.
    void regenerateThumbnails();

    bool thumbnailsPending() const { return m_thumbPending; }
    bool palettePending() const { return m_palettePending; }
    /// Incremented by every thumbnail request; a result of an older one is dropped.
    uint64_t thumbnailGeneration() const { return m_thumbGeneration; }
    /// The thumbnails last shown (all null before the first result or after an error).
    const TextureThumbnails& thumbnails() const { return m_thumbs; }
    const std::vector<bake::PaletteColor>& pickedPalette() const { return m_picked; }
    /// "#rrggbb" lines of the picked palette, as Copy hex puts them on the clipboard.
    QString pickedHexText() const;

    QLineEdit* specField() { return m_spec; }
    QLineEdit* tilesField() { return m_tiles; }
    QLineEdit* normalField() { return m_normal; }
    QSpinBox* seedBox() { return m_seed; }
    QPushButton* applyButton() { return m_apply; }
    QPushButton* removeButton() { return m_remove; }
    QPushButton* pickButton() { return m_pick; }
    QPushButton* copyHexButton() { return m_copyHex; }
    QComboBox* pickMethod() { return m_method; }
    QLabel* statusLabel() { return m_status; }
    QLabel* thumbnailStatus() { return m_thumbStatus; }
    QLabel* thumbnailLabel(int map) { return m_thumbLabels[map]; } ///< 0 diffuse, 1 roughness, 2 normal
    QWidget* specSwatches() { return m_specSwatchHost; }
    QWidget* pickedSwatches() { return m_pickedSwatchHost; }

private:
    void refresh();
    void setStatus(const QString& error);
    void showThumbnails(const TextureThumbnails& t);
    void showPicked();
    /// The selection's texture block in the current model (null: none or nothing selected).
    const TextureProject* current() const;
    bool hasTarget() const;
    QString targetName() const;
    QString previewKey() const;

    Document* m_doc;
    Target m_kind = Target::None;
    int m_index = -1;
    QLabel *m_header = nullptr, *m_status = nullptr, *m_thumbStatus = nullptr, *m_pickStatus = nullptr;
    QLineEdit *m_spec = nullptr, *m_tiles = nullptr, *m_normal = nullptr;
    QSpinBox* m_seed = nullptr;
    QPushButton *m_apply = nullptr, *m_remove = nullptr, *m_pick = nullptr, *m_copyHex = nullptr;
    QComboBox* m_method = nullptr;
    QLabel* m_thumbLabels[3] = {};
    QWidget *m_specSwatchHost = nullptr, *m_pickedSwatchHost = nullptr;
    QGridLayout *m_specSwatches = nullptr, *m_pickedSwatches = nullptr;
    TextureThumbnails m_thumbs;
    std::vector<bake::PaletteColor> m_picked;
    uint64_t m_thumbGeneration = 0, m_paletteGeneration = 0;
    bool m_thumbPending = false, m_palettePending = false;
    QString m_shownKey;    ///< what the thumbnails were last requested for
    QString m_shownFields; ///< the block the fields were last filled from
};

} // namespace viscera::studio
