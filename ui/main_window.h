// The editor's main window: outliner, properties, method panel, log and the viewport, around
// one document and one engine. The window owns the document (the GUI thread's copy of the scene)
// and the undo stack; every change is an EditCommand that updates the document and is sent, as a
// value, to the render thread. GUI thread only; nothing here waits on rendering.
#pragma once

#include <QElapsedTimer>
#include <QMainWindow>
#include <QSet>
#include <QTimer>
#include <QUndoStack>

#include <filesystem>
#include <functional>
#include <memory>
#include <vector>

#include "frame_view.h"
#include "property_panel.h"
#include "retile/edit.h"
#include "retile/engine.h"

class QTreeWidget;
class QTreeWidgetItem;
class QPlainTextEdit;
class QFormLayout;
class QLabel;
class QComboBox;
class QSpinBox;
class QCheckBox;
class QWidget;
class QMenu;
class QDockWidget;
class QGroupBox;

namespace retile::ui {

struct EditorOptions {
  // Render at 1/scale of the viewport at rest, and while edits come at 1/(scale x previewBlock)
  // (RenderSession::setPreview): lavapipe traces well under a million samples a second, so the
  // frames of a drag stay quick and the picture at rest is sharp enough to judge a material.
  int renderScale = 2;
  int previewBlock = 2;
  QSize initialRenderSize{};  // fixed render size (tests); empty: follow the viewport
  // Frame the image as the scene's resolution frames it (its width : height, fitted into the
  // viewport and letterboxed); else the image fills the viewport, widening or narrowing the view.
  // On by default: filling a viewport narrower than a 16:9 scene cuts off its sides, and a file
  // should open showing what its camera frames, what `retile render` renders.
  bool cameraFraming = true;
  // Restore the window's geometry and dock layout from QSettings and save them on close (the app;
  // tests leave it off so that one test's layout never reaches the next).
  bool keepLayout = false;
};

class MainWindow : public QMainWindow {
  Q_OBJECT
 public:
  MainWindow(Scene scene, std::filesystem::path file, EditorOptions options = {}, QWidget* parent = nullptr);
  ~MainWindow() override;

  // Opens a scene file; on failure shows the error and keeps the current scene. Returns success.
  bool openFile(const std::filesystem::path& file);
  // A file has been opened (here or by the command line before the window existed): it goes to
  // Open Recent, and what its import warned about is logged and announced where it is seen (the
  // viewport's notice, the status bar, the Log raised).
  void opened(const std::filesystem::path& file, const std::vector<std::string>& warnings);
  // A line the user should read now: the status bar for a while, and the log.
  void notify(const QString& text);
  bool saveTo(const std::filesystem::path& file);
  // Appends a line to the Log dock (a warning is logged once per document).
  void log(const QString& line);
  // Asks for a .retile file (the "saveAsDialog") and saves there.
  bool saveAs();
  // The picture the viewport shows (the denoised view where it is denoised; no overlays), at its
  // render resolution: EXR linear with the raw accumulation and the guide channels, PNG through
  // the viewport's view, exposure and gamma. Atomic; an error is shown. saveImage asks for the
  // file (the "saveImageDialog").
  bool saveImageTo(const std::filesystem::path& file);
  bool saveImage();

  const Scene& scene() const { return doc_.scene(); }
  std::uint64_t documentVersion() const { return doc_.version(); }
  QUndoStack* undoStack() { return &undo_; }
  FrameView* viewport() { return view_; }
  PropertyPanel* properties() { return panel_; }
  class LiveChart* chart() {
    return chart_;
  }
  class NodeGraphView* graph() {
    return graph_;
  }
  Engine* engine() { return engine_.get(); }
  QTreeWidget* outliner() { return outliner_; }
  NodeId selection() const { return selection_; }  // the last picked object: gizmo, Properties
  // Every selected object (Ctrl+click in the viewport or the outliner adds and removes); moves,
  // turns and scales apply to all of them as one undo step.
  const std::vector<NodeId>& selectedObjects() const { return selected_; }
  void toggleSelected(NodeId object);
  void select(NodeId object);
  // Applies an edit through the undo stack (dragId > 0 merges a drag into one step).
  void edit(const Edit& before, const Edit& after, const QString& text, int dragId = 0);
  QString lastError() const { return lastError_; }
  bool paused() const { return paused_; }
  // Autosave: writes the document to the newest of three rotating recovery files when it changed.
  bool autosave();
  // Recovery files left by a session that did not close cleanly (newest first).
  static QStringList recoveryCandidates();
  static QString recoveryDirectory();

 protected:
  void closeEvent(QCloseEvent* e) override;
  void dragEnterEvent(QDragEnterEvent* e) override;
  void dropEvent(QDropEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;
  void resizeEvent(QResizeEvent* e) override;

 private:
  void buildMenus();
  void connectViewport();  // the viewport's signals: picking, focus points, the inspector, drags
  void connectDrags();
  void startAutosave();
  // Asks to save unsaved changes; false when the user cancels.
  bool maybeSave();
  void refreshGraph();
  void updateGizmo();
  void applySelection();  // shows selected_ and selection_ everywhere (viewport, engine, graph, panel, outliner)
  // One undo step changing every selected object; `what` has %1 for the object's name or count.
  void editSelected(const std::function<void(Object&)>& change, const QString& what);
  Vec3 pivot(const Object& o) const;  // where the gizmo sits and rotation/scale turn about
  void replaceDocument(Scene scene, const std::filesystem::path& file);
  // Shows the document through the view its scene asks for (RenderSettings::view), if it names one.
  void applySceneView();
  void buildDocks();
  QTreeWidget* buildOutliner();
  QGroupBox* buildDisplayBox(QWidget* parent);
  QDockWidget* addDock(const QString& title, const char* name, QWidget* content, Qt::DockWidgetArea area);
  void startEngine(Scene scene);
  void rebuildOutliner();
  void rebuildProperties();
  void onFrame();
  void showError(const QString& title, const QString& message);
  bool applyToDocument(const Edit& e);
  void updateRenderSize();
  QSize desiredRenderSize() const;
  void updateTitle();  // the file's name, and [*] while there are unsaved changes
  // The file's name and its folder's ("scene.json (kitchen)": Tungsten scenes are all scene.json).
  QString documentName() const;
  void rememberRecent(const std::filesystem::path& file);
  void rebuildRecentMenu();
  void editCamera(const std::function<void(Camera&)>& change, const QString& what);
  void frameSelected();
  void showTool();  // the active tool in the status bar

  EditorOptions options_;
  Document doc_;
  std::filesystem::path file_;
  std::filesystem::path imageFolder_;  // of the last image saved (saveImage's dialog starts there)
  std::unique_ptr<Engine> engine_;
  QUndoStack undo_;
  NodeId selection_ = kNoNode;
  std::vector<NodeId> selected_;  // includes selection_
  // The editor's method at start: the library's, denoised, so that a pass shows its growing regions.
  static MethodSettings editorMethod() {
    MethodSettings m;
    m.denoise = true;
    return m;
  }
  class MethodPanel* methodPanel_ = nullptr;  // owns the method the engine renders with
  bool paused_ = false;
  void setRenderPaused(bool paused);  // the engine, the viewport's banner and the log
  int dragCounter_ = 0;
  QString lastError_;
  QSize renderSize_;

  FrameView* view_ = nullptr;
  QTreeWidget* outliner_ = nullptr;
  PropertyPanel* panel_ = nullptr;
  PropertyPanel* renderPanel_ = nullptr;
  class NodeGraphView* graph_ = nullptr;
  bool graphRefreshQueued_ = false;
  bool outlinerRefreshQueued_ = false;
  FrameView::Gizmo gizmo_;
  QTimer resizeTimer_;
  float gizmoLength_ = 0.0f;  // world length of the gizmo's arrows
  QLabel* inspector_ = nullptr;
  class LiveChart* chart_ = nullptr;
  QString pixelText_, regionText_;
  QElapsedTimer focusTimer_;
  QComboBox* displayView_ = nullptr;  // the viewport's OCIO view
  QPlainTextEdit* log_ = nullptr;
  PropertyPanel* panelEdit_ = nullptr;       // the panel whose own edit is being applied (it shows it already)
  QSet<QString> loggedWarnings_;             // of the current document: each is logged once
  std::vector<std::string> importWarnings_;  // the current document's import's
  QLabel* status_ = nullptr;
  QLabel* toolLabel_ = nullptr;
  QMenu* recentMenu_ = nullptr;
  int autosaveSlot_ = 0;
  int autosavedIndex_ = -1;  // undo index at the last autosave
  std::uint64_t framesSeen_ = 0;
  qint64 fpsStart_ = 0;
  double fps_ = 0;
};

}  // namespace retile::ui
