<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="en" sourcelanguage="en">
<context>
    <name>liversim::AccuracyStudyDialog</name>
    <message numerus="yes">
        <source>Done: %n run(s). Select one and press Use This Setting to advance the running liver with it.</source>
        <translation>
            <numerusform>Done: %n run. Select it and press Use This Setting to advance the running liver with it.</numerusform>
            <numerusform>Done: %n runs. Select one and press Use This Setting to advance the running liver with it.</numerusform>
        </translation>
    </message>
</context>
<context>
    <name>liversim::EditorTissuePanel</name>
    <message numerus="yes">
        <source>%n ball(s)</source>
        <translation>
            <numerusform>%n ball</numerusform>
            <numerusform>%n balls</numerusform>
        </translation>
    </message>
</context>
<context>
    <name>liversim::MainWindow</name>
    <message numerus="yes">
        <source>Took %n specimen(s) out of the field.</source>
        <translation>
            <numerusform>Took %n specimen out of the field.</numerusform>
            <numerusform>Took %n specimens out of the field.</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source> | %n piece(s) cut free: lift out or Session ▸ Remove Specimen</source>
        <translation>
            <numerusform> | %n piece cut free: lift out or Session ▸ Remove Specimen</numerusform>
            <numerusform> | %n pieces cut free: lift out or Session ▸ Remove Specimen</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source> | %n specimen(s) taken out</source>
        <translation>
            <numerusform> | %n specimen taken out</numerusform>
            <numerusform> | %n specimens taken out</numerusform>
        </translation>
    </message>
</context>
<context>
    <name>liversim::ScenarioPanel</name>
    <message numerus="yes">
        <source>%n lesion(s)</source>
        <translation>
            <numerusform>%n lesion</numerusform>
            <numerusform>%n lesions</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>, %n hidden</source>
        <translation>
            <numerusform>, %n hidden</numerusform>
            <numerusform>, %n hidden</numerusform>
        </translation>
    </message>
</context>
<context>
    <name>liversim::TrainingCentreControl</name>
    <message numerus="yes">
        <source>Training centre: %1 not reached, %n session(s) waiting</source>
        <translation>
            <numerusform>Training centre: %1 not reached, %n session waiting</numerusform>
            <numerusform>Training centre: %1 not reached, %n sessions waiting</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>Training centre: up to date at %1, %n session(s) uploaded</source>
        <translation>
            <numerusform>Training centre: up to date at %1, %n session uploaded</numerusform>
            <numerusform>Training centre: up to date at %1, %n sessions uploaded</numerusform>
        </translation>
    </message>
</context>
</TS>
