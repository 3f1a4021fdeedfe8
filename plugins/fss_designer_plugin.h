#pragma once
/// \file fss_designer_plugin.h
/// The Qt Designer plugin of FSS: one QDesignerCustomWidgetCollectionInterface offering every FSS widget
/// in Designer's widget box (group "FSS"). Adding a widget is one addWidget<...>() line in the
/// collection's constructor (fss_designer_plugin.cpp).

#include <QIcon>
#include <QObject>
#include <QSize>
#include <QString>
#include <QtUiPlugin/QDesignerCustomWidgetCollectionInterface>
#include <QtUiPlugin/QDesignerCustomWidgetInterface>

#include <functional>
#include <memory>
#include <vector>

namespace fss::designer {

/// What Designer needs to know about one widget class.
struct WidgetDescription {
    QString className;   ///< fully qualified C++ class name, e.g. "fss::widgets::VtkView"
    QString includeFile; ///< header uic includes, e.g. "fss/widgets/vtk_view.h"
    QString objectName;  ///< default object name of a new instance in a form, e.g. "vtkView"
    QString toolTip;     ///< one line shown in the widget box
    QString whatsThis;   ///< longer description
    QSize defaultSize;   ///< size of a new instance in a form
    std::function<QWidget*(QWidget*)> create; ///< makes an instance with the given parent
};

/// QDesignerCustomWidgetInterface for one WidgetDescription. Not a QObject: Designer only calls it through
/// the collection's list.
class CustomWidget final : public QDesignerCustomWidgetInterface {
public:
    explicit CustomWidget(WidgetDescription description) : d_(std::move(description)) {}

    QString name() const override { return d_.className; }
    QString group() const override;
    QString toolTip() const override { return d_.toolTip; }
    QString whatsThis() const override { return d_.whatsThis; }
    QString includeFile() const override { return d_.includeFile; }
    QIcon icon() const override { return {}; }
    bool isContainer() const override { return false; }
    QWidget* createWidget(QWidget* parent) override { return d_.create(parent); }
    bool isInitialized() const override { return initialized_; }
    void initialize(QDesignerFormEditorInterface*) override { initialized_ = true; }
    QString domXml() const override;

private:
    WidgetDescription d_;
    bool initialized_ = false;
};

/// The plugin object Designer loads: the list of FSS widgets.
class WidgetCollection final : public QObject, public QDesignerCustomWidgetCollectionInterface {
    Q_OBJECT
    Q_PLUGIN_METADATA(IID "org.qt-project.Qt.QDesignerCustomWidgetCollectionInterface")
    Q_INTERFACES(QDesignerCustomWidgetCollectionInterface)
public:
    /// The group every FSS widget appears under in Designer's widget box.
    static constexpr const char* kGroup = "FSS";

    explicit WidgetCollection(QObject* parent = nullptr);
    QList<QDesignerCustomWidgetInterface*> customWidgets() const override;

private:
    /// Offers widget class W (constructible as W(QWidget* parent)).
    template <class W> void addWidget(WidgetDescription description) {
        description.create = [](QWidget* parent) -> QWidget* { return new W(parent); };
        widgets_.push_back(std::make_unique<CustomWidget>(std::move(description)));
    }

    std::vector<std::unique_ptr<CustomWidget>> widgets_;
};

} // namespace fss::designer
