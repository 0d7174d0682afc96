<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="zh_CN" sourcelanguage="en">
<context>
    <name>ForceChart</name>
    <message>
        <source>Time (s)</source>
        <translation>时间 (s)</translation>
    </message>
    <message>
        <source>Force (N)</source>
        <translation>力 (N)</translation>
    </message>
</context>
<context>
    <name>QObject</name>
    <message>
        <source>%1 could not be written: %2</source>
        <translation>无法写入 %1：%2</translation>
    </message>
</context>
<context>
    <name>SessionReading</name>
    <message>
        <source>Reading the frames of session %1…</source>
        <translation>正在读取会话 %1 的帧…</translation>
    </message>
    <message>
        <source>Cancel</source>
        <translation>取消</translation>
    </message>
    <message>
        <source>Reading a session</source>
        <translation>正在读取会话</translation>
    </message>
    <message>
        <source>The force trace of session %1 was not read: reading was cancelled. Open the session again to read it.</source>
        <translation>会话 %1 的力曲线未读取：读取已取消。再次打开该会话即可读取。</translation>
    </message>
    <message>
        <source>Reading the left hand&apos;s frames of session %1…</source>
        <translation>正在读取会话 %1 的左手帧…</translation>
    </message>
</context>
<context>
    <name>liversim</name>
    <message>
        <source>Check that the folder exists and can be written and that its disk is mounted, or start LiverSim with another file (liversim --database FILE).</source>
        <translation>请检查文件夹是否存在且可写、其磁盘是否已挂载，或用另一个文件启动 LiverSim（liversim --database FILE）。</translation>
    </message>
    <message>
        <source>Make the file and its folder writable, or start LiverSim with another file (liversim --database FILE). The sessions already saved in it are kept.</source>
        <translation>请使该文件及其文件夹可写，或用另一个文件启动 LiverSim（liversim --database FILE）。其中已保存的会话会保留。</translation>
    </message>
    <message>
        <source>Free space on the disk, then start a new session. The sessions already saved are kept.</source>
        <translation>请释放磁盘空间，然后开始新的会话。已保存的会话会保留。</translation>
    </message>
    <message>
        <source>Keep a copy of the file and restore it from a backup (sqlite3&apos;s .recover command can rescue what is left), or start LiverSim with a new file (liversim --database FILE).</source>
        <translation>请保留该文件的副本并从备份恢复（sqlite3 的 .recover 命令可挽救剩余内容），或用新文件启动 LiverSim（liversim --database FILE）。</translation>
    </message>
    <message>
        <source>Choose a LiverSim sessions database, or a new file name (liversim --database FILE).</source>
        <translation>请选择一个 LiverSim 会话数据库，或一个新文件名（liversim --database FILE）。</translation>
    </message>
    <message>
        <source>Open it with the newer LiverSim that wrote it, or start this one with another file (liversim --database FILE).</source>
        <translation>请用写入它的较新版 LiverSim 打开，或用另一个文件启动本程序（liversim --database FILE）。</translation>
    </message>
    <message>
        <source>Start LiverSim again to make a new sessions database there, or restore the file from a backup. Until then, sessions are not recorded.</source>
        <translation>请重新启动 LiverSim 以在该位置新建会话数据库，或从备份恢复该文件。在此之前，会话不会被录制。</translation>
    </message>
    <message>
        <source>Check the login name and password in the training centre settings, or ask the server&apos;s administrator for the permission. Sessions keep being recorded on this workstation.</source>
        <translation>请检查培训中心设置中的登录名和密码，或请服务器管理员授予权限。本工作站会继续记录训练。</translation>
    </message>
</context>
<context>
    <name>liversim::AccuracyPanel</name>
    <message>
        <source>explicit</source>
        <translation>显式</translation>
    </message>
    <message>
        <source>implicit</source>
        <translation>隐式</translation>
    </message>
    <message>
        <source>%1 (%2, order %3)</source>
        <translation>%1（%2，%3 阶）</translation>
    </message>
    <message>
        <source> ms</source>
        <translation> ms</translation>
    </message>
    <message>
        <source>Step:</source>
        <translation>步长：</translation>
    </message>
    <message>
        <source> µm</source>
        <translation> µm</translation>
    </message>
    <message>
        <source>Error tolerance:</source>
        <translation>误差容差：</translation>
    </message>
    <message>
        <source>Local error allowed per step (node positions).</source>
        <translation>每步允许的局部误差（节点位置）。</translation>
    </message>
    <message>
        <source>Apply</source>
        <translation>应用</translation>
    </message>
    <message>
        <source>Rebuilds the model with this integrator and carries the liver&apos;s current motion over.</source>
        <translation>使用此时间积分器重建模型，并沿用肝脏当前的运动状态。</translation>
    </message>
    <message>
        <source>Integrator:</source>
        <translation>时间积分器：</translation>
    </message>
    <message>
        <source>In use: %1</source>
        <translation>当前使用：%1</translation>
    </message>
    <message>
        <source>Rebuilding the model…</source>
        <translation>正在重建模型…</translation>
    </message>
    <message>
        <source>Not applied: %1</source>
        <translation>未应用：%1</translation>
    </message>
    <message>
        <source>largest stable</source>
        <translation>最大稳定步长</translation>
    </message>
    <message>
        <source>First step:</source>
        <translation>初始步长：</translation>
    </message>
    <message>
        <source>step %1 ms</source>
        <translation>步长 %1 ms</translation>
    </message>
    <message>
        <source>largest stable step</source>
        <translation>最大稳定步长</translation>
    </message>
    <message>
        <source>%1, first %2, tolerance %3 µm</source>
        <translation>%1，初始%2，容差 %3 µm</translation>
    </message>
    <message>
        <source>%1, %2</source>
        <translation>%1，%2</translation>
    </message>
    <message>
        <source>Central difference</source>
        <translation>中心差分</translation>
    </message>
    <message>
        <source>Runge–Kutta 4</source>
        <translation>四阶龙格-库塔 (RK4)</translation>
    </message>
    <message>
        <source>Dormand–Prince 5(4)</source>
        <translation>Dormand–Prince 5(4)</translation>
    </message>
    <message>
        <source>Backward Euler</source>
        <translation>后向欧拉</translation>
    </message>
    <message>
        <source>BDF2</source>
        <translation>BDF2</translation>
    </message>
    <message>
        <source>Compare Integrators…</source>
        <translation>比较积分器…</translation>
    </message>
    <message>
        <source>Measure what each integrator and step costs in time and how far it is from a reference (the accuracy study)</source>
        <translation>测量每种积分器和步长的时间开销及其与参考解的偏差（精度研究）</translation>
    </message>
</context>
<context>
    <name>liversim::AccuracyStudyDialog</name>
    <message>
        <source>Elastic (neo-Hookean)</source>
        <translation>弹性（新胡克）</translation>
    </message>
    <message>
        <source>Viscoelastic</source>
        <translation>黏弹性</translation>
    </message>
    <message>
        <source>Viscoelastic and viscoplastic</source>
        <translation>黏弹性与黏塑性</translation>
    </message>
    <message>
        <source>Elastic with fibres</source>
        <translation>弹性加纤维</translation>
    </message>
    <message>
        <source>Accuracy Study: What Accuracy Costs in Time</source>
        <translation>精度研究：精度的时间代价</translation>
    </message>
    <message>
        <source> tetrahedra</source>
        <translation> 个四面体</translation>
    </message>
    <message>
        <source>Size of the built-in liver the study runs on (about this many).</source>
        <translation>研究所用内置肝脏的规模（约为此数）。</translation>
    </message>
    <message>
        <source>The tissue laws simulated (docs/accuracy-study.md gives the parameters).</source>
        <translation>所模拟的组织本构（参数见 docs/accuracy-study.md）。</translation>
    </message>
    <message>
        <source> ms</source>
        <translation> ms</translation>
    </message>
    <message>
        <source>Simulated time of each run: the liver is pulled at its marked point, the force rising smoothly to %1 N.</source>
        <translation>每次运行的模拟时长：在肝脏标记点施加拉力，力平滑上升至 %1 N。</translation>
    </message>
    <message>
        <source>Fixed-step schemes run at 1, 0.5 and 0.25 ms; Dormand–Prince at tolerances 0.1, 0.001 and 0.00001 µm. Errors are against Runge–Kutta 4 at 1/64 of the smallest step.</source>
        <translation>定步长方法以 1、0.5 和 0.25 ms 运行；Dormand–Prince 以 0.1、0.001 和 0.00001 µm 容差运行。误差以最小步长 1/64 的四阶龙格–库塔为参考。</translation>
    </message>
    <message>
        <source>&amp;Run Study</source>
        <translation>运行研究(&amp;R)</translation>
    </message>
    <message>
        <source>Cancel</source>
        <translation>取消</translation>
    </message>
    <message>
        <source>Choose the runs and press Run Study.</source>
        <translation>选择要运行的内容，然后按“运行研究”。</translation>
    </message>
    <message>
        <source>Integrator</source>
        <translation>积分器</translation>
    </message>
    <message>
        <source>Setting</source>
        <translation>设置</translation>
    </message>
    <message>
        <source>Mean step (ms)</source>
        <translation>平均步长（ms）</translation>
    </message>
    <message>
        <source>Largest error (µm)</source>
        <translation>最大误差（µm）</translation>
    </message>
    <message>
        <source>Error at the load (µm)</source>
        <translation>加载点误差（µm）</translation>
    </message>
    <message>
        <source>Cost (s per simulated s)</source>
        <translation>开销（每模拟秒所需秒数）</translation>
    </message>
    <message>
        <source>Against real time</source>
        <translation>相对实时</translation>
    </message>
    <message>
        <source>Best trade-off</source>
        <translation>最佳权衡</translation>
    </message>
    <message>
        <source>Largest distance of any node from the reference at the end.</source>
        <translation>结束时任一节点与参考解的最大距离。</translation>
    </message>
    <message>
        <source>Wall time of the steps per simulated second, on one thread of this machine: below 1 runs faster than real time.</source>
        <translation>本机单线程上每模拟秒的步进耗时：小于 1 即快于实时。</translation>
    </message>
    <message>
        <source>No other run is both more accurate and cheaper.</source>
        <translation>没有其他运行既更精确又更省时。</translation>
    </message>
    <message>
        <source>&amp;Use This Setting</source>
        <translation>使用此设置(&amp;U)</translation>
    </message>
    <message>
        <source>Advance the running liver with the selected run&apos;s integrator and step.</source>
        <translation>用所选运行的积分器和步长推进正在运行的肝脏。</translation>
    </message>
    <message>
        <source>&amp;Save as CSV…</source>
        <translation>另存为 CSV(&amp;S)…</translation>
    </message>
    <message>
        <source>Liver:</source>
        <translation>肝脏：</translation>
    </message>
    <message>
        <source>Tissue:</source>
        <translation>组织：</translation>
    </message>
    <message>
        <source>Integrators:</source>
        <translation>积分器：</translation>
    </message>
    <message>
        <source>Duration:</source>
        <translation>时长：</translation>
    </message>
    <message>
        <source>Save the study</source>
        <translation>保存研究结果</translation>
    </message>
    <message>
        <source>CSV (*.csv)</source>
        <translation>CSV（*.csv）</translation>
    </message>
    <message>
        <source>A study is running: wait for it or cancel it first.</source>
        <translation>研究正在运行：请等待其完成或先取消。</translation>
    </message>
    <message>
        <source>Check at least one integrator to study.</source>
        <translation>请至少勾选一个要研究的积分器。</translation>
    </message>
    <message>
        <source>Starting…</source>
        <translation>正在开始…</translation>
    </message>
    <message>
        <source>Cancelling…</source>
        <translation>正在取消…</translation>
    </message>
    <message>
        <source>There is no result to save yet: run the study first.</source>
        <translation>尚无可保存的结果：请先运行研究。</translation>
    </message>
    <message>
        <source>Could not write %1: check that its folder exists and is writable, and that the disk has space.</source>
        <translation>无法写入 %1：请检查其文件夹是否存在且可写，以及磁盘是否有空间。</translation>
    </message>
    <message>
        <source>Saved %1.</source>
        <translation>已保存 %1。</translation>
    </message>
    <message>
        <source>Run %1 of %2: %3</source>
        <translation>第 %1 次运行，共 %2 次：%3</translation>
    </message>
    <message>
        <source>Cancelled: no result was kept.</source>
        <translation>已取消：未保留任何结果。</translation>
    </message>
    <message>
        <source>The study stopped: %1</source>
        <translation>研究已停止：%1</translation>
    </message>
    <message numerus="yes">
        <source>Done: %n run(s). Select one and press Use This Setting to advance the running liver with it.</source>
        <translation>
            <numerusform>完成：%n 次运行。选择一次并按“使用此设置”，即可用它推进正在运行的肝脏。</numerusform>
        </translation>
    </message>
    <message>
        <source>tolerance %1 µm</source>
        <translation>容差 %1 µm</translation>
    </message>
    <message>
        <source>step %1 ms</source>
        <translation>步长 %1 ms</translation>
    </message>
    <message>
        <source>%1× faster</source>
        <translation>快 %1 倍</translation>
    </message>
    <message>
        <source>%1× slower</source>
        <translation>慢 %1 倍</translation>
    </message>
    <message>
        <source> (stability-limited)</source>
        <translation>（受稳定性限制）</translation>
    </message>
    <message>
        <source>yes</source>
        <translation>是</translation>
    </message>
</context>
<context>
    <name>liversim::CalibrationDialog</name>
    <message>
        <source>Calibrate %1</source>
        <translation>校准%1</translation>
    </message>
    <message>
        <source>Device calibration:</source>
        <translation>设备校准：</translation>
    </message>
    <message>
        <source>Stylus at:</source>
        <translation>触笔位置：</translation>
    </message>
    <message>
        <source> ×</source>
        <translation> ×</translation>
    </message>
    <message>
        <source>Scene distance per device distance: above 1 the tool moves farther than the hand, and forces are felt weaker by the same factor</source>
        <translation>场景移动距离与设备移动距离之比：大于 1 时器械的移动距离大于手的移动距离，感受到的力也按同一倍数减弱</translation>
    </message>
    <message>
        <source>Motion scale:</source>
        <translation>运动比例：</translation>
    </message>
    <message>
        <source> mm</source>
        <translation> mm</translation>
    </message>
    <message>
        <source>Scene point of the device&apos;s origin (x, y, z):</source>
        <translation>设备原点在场景中的位置 (x, y, z)：</translation>
    </message>
    <message>
        <source>Device axes in the scene:</source>
        <translation>设备坐标轴在场景中的方向：</translation>
    </message>
    <message>
        <source>&amp;Align with the view</source>
        <translation>与视图对齐(&amp;A)</translation>
    </message>
    <message>
        <source>Turn the device&apos;s axes to the screen&apos;s: right, up and toward you</source>
        <translation>将设备坐标轴转到与屏幕一致：向右、向上、朝向您</translation>
    </message>
    <message>
        <source>&amp;Centre here</source>
        <translation>在此居中(&amp;C)</translation>
    </message>
    <message>
        <source>Hold the stylus in the middle of its workspace and press: the tool will be just in front of the liver there</source>
        <translation>将触笔握持在其工作空间中央并按下此按钮：触笔在该处时器械将正好位于肝脏前方</translation>
    </message>
    <message>
        <source>First button</source>
        <translation>第一个按钮</translation>
    </message>
    <message>
        <source>Second button</source>
        <translation>第二个按钮</translation>
    </message>
    <message>
        <source>Either button</source>
        <translation>任一按钮</translation>
    </message>
    <message>
        <source>Held, this button closes the forceps or lets the scalpel cut</source>
        <translation>按住此按钮时抓钳闭合，或手术刀进行切割</translation>
    </message>
    <message>
        <source>Grasp / cut button:</source>
        <translation>抓取/切割按钮：</translation>
    </message>
    <message>
        <source>The device has reported no position yet: is it connected?</source>
        <translation>设备尚未报告位置：是否已连接？</translation>
    </message>
    <message>
        <source>Centred: the stylus is now just in front of the liver.</source>
        <translation>已居中：触笔当前位置对应肝脏正前方。</translation>
    </message>
    <message>
        <source>%1, %2, %3 mm</source>
        <translation>%1, %2, %3 mm</translation>
    </message>
    <message>
        <source>no position yet</source>
        <translation>尚无位置</translation>
    </message>
    <message>
        <source>(%1, %2, %3)</source>
        <translation>(%1, %2, %3)</translation>
    </message>
    <message>
        <source>x → %1, y → %2, z → %3</source>
        <translation>x → %1，y → %2，z → %3</translation>
    </message>
</context>
<context>
    <name>liversim::DeviceControl</name>
    <message>
        <source>Trajectory to play</source>
        <translation>要播放的轨迹</translation>
    </message>
    <message>
        <source>Trajectories (*.txt *.trajectory);;All files (*)</source>
        <translation>轨迹文件 (*.txt *.trajectory);;所有文件 (*)</translation>
    </message>
    <message>
        <source>Choose a trajectory file to play.</source>
        <translation>请选择要播放的轨迹文件。</translation>
    </message>
    <message>
        <source>Cannot play the trajectory: %1</source>
        <translation>无法播放轨迹：%1</translation>
    </message>
    <message>
        <source>The Phantom Omni is not available: %1</source>
        <translation>Phantom Omni 不可用：%1</translation>
    </message>
    <message>
        <source>Choose a recorded session to replay.</source>
        <translation>请选择要回放的训练记录。</translation>
    </message>
    <message>
        <source>Cannot run the device: %1</source>
        <translation>无法运行设备：%1</translation>
    </message>
    <message>
        <source>The mouse moves the tool: press on the liver to put the tool chosen in the Tool panel there.</source>
        <translation>由鼠标移动器械：在肝脏上按下鼠标，即可将“器械”面板中所选的器械放到该处。</translation>
    </message>
    <message>
        <source>%1 moves the tool chosen in the Tool panel.</source>
        <translation>由 %1 移动“器械”面板中所选的器械。</translation>
    </message>
    <message>
        <source>The device</source>
        <translation>设备</translation>
    </message>
    <message>
        <source>%1 stopped: %2. The mouse moves the tool now; choose the device again once it is back.</source>
        <translation>%1已停止：%2。现在由鼠标移动器械；设备恢复后请重新选择它。</translation>
    </message>
    <message>
        <source>the scripted device</source>
        <translation>脚本设备</translation>
    </message>
    <message>
        <source>the device</source>
        <translation>设备</translation>
    </message>
    <message>
        <source>calibrated</source>
        <translation>已校准</translation>
    </message>
    <message>
        <source>not calibrated: put the stylus in its inkwell (or move it through its whole range), then open this dialog again</source>
        <translation>未校准：请将触笔放入笔座（或在其整个活动范围内移动一遍），然后重新打开此对话框</translation>
    </message>
    <message>
        <source>There is no sessions database.</source>
        <translation>没有训练记录数据库。</translation>
    </message>
    <message>
        <source>Session %1 is not yours to replay: trainees replay their own sessions (an instructor may replay any).</source>
        <translation>会话 %1 不属于您，无法回放：学员只能回放自己的会话（教师可回放任何会话）。</translation>
    </message>
    <message>
        <source>Session %1 is not replayed: reading it was cancelled.</source>
        <translation>会话 %1 未回放：读取已取消。</translation>
    </message>
    <message>
        <source>Session %1 has no device input to replay.</source>
        <translation>训练记录 %1 没有可回放的设备输入。</translation>
    </message>
    <message>
        <source>Cannot replay session %1: %2</source>
        <translation>无法回放训练记录 %1：%2</translation>
    </message>
    <message>
        <source>%1: %2, %3, %4 (%5)</source>
        <translation>%1: %2，%3，%4（%5）</translation>
    </message>
    <message>
        <source>No recorded session has device input to replay.</source>
        <translation>没有包含可回放设备输入的训练记录。</translation>
    </message>
    <message>
        <source>Replay a session</source>
        <translation>回放训练记录</translation>
    </message>
    <message>
        <source>Session:</source>
        <translation>训练记录：</translation>
    </message>
    <message>
        <source>Trajectory for the left hand</source>
        <translation>左手的轨迹</translation>
    </message>
    <message>
        <source>Cannot play the trajectory in the left hand: %1</source>
        <translation>无法在左手播放轨迹：%1</translation>
    </message>
    <message>
        <source> In the left hand, %1 moves the tool chosen below.</source>
        <translation>左手由 %1 移动下方所选的器械。</translation>
    </message>
    <message>
        <source>The Omni cannot be the left hand&apos;s: %1</source>
        <translation>Omni 不能用作左手设备：%1</translation>
    </message>
    <message>
        <source>The left hand&apos;s Omni keeps the name “%1”: a Touch Setup name is 1 to %2 printable characters</source>
        <translation>左手的 Phantom Omni 保留名称“%1”：Touch Setup 中的名称为 1 到 %2 个可打印字符</translation>
    </message>
</context>
<context>
    <name>liversim::DevicePanel</name>
    <message>
        <source>Mouse and keyboard</source>
        <translation>鼠标和键盘</translation>
    </message>
    <message>
        <source>Phantom Omni (OpenHaptics)</source>
        <translation>Phantom Omni (OpenHaptics)</translation>
    </message>
    <message>
        <source>Scripted trajectory…</source>
        <translation>脚本轨迹…</translation>
    </message>
    <message>
        <source>Replay of a session…</source>
        <translation>回放训练记录…</translation>
    </message>
    <message>
        <source>Move the tool with the mouse in the viewport</source>
        <translation>在视口中用鼠标移动器械</translation>
    </message>
    <message>
        <source>Play a trajectory file (time s, x y z mm, buttons per line) on the tool</source>
        <translation>用轨迹文件驱动器械（每行：时间 s，x y z mm，按钮）</translation>
    </message>
    <message>
        <source>&amp;Calibrate…</source>
        <translation>校准(&amp;C)…</translation>
    </message>
    <message>
        <source>The haptic servo loop: tick rate, tick periods (median and 99th percentile), late ticks, and the safety limits it applied</source>
        <translation>力反馈伺服循环：节拍频率、节拍周期（中位数和第 99 百分位数）、超时节拍数，以及所施加的安全限制</translation>
    </message>
    <message>
        <source>Phantom Omni (OpenHaptics): not found</source>
        <translation>Phantom Omni (OpenHaptics)：未找到</translation>
    </message>
    <message>
        <source>The Phantom Omni found through OpenHaptics</source>
        <translation>通过 OpenHaptics 找到的 Phantom Omni</translation>
    </message>
    <message>
        <source>Not available: %1. Choose it again to look again.</source>
        <translation>不可用：%1。再次选择此项可重新查找。</translation>
    </message>
    <message>
        <source>Map the device&apos;s workspace onto the scene and choose its buttons</source>
        <translation>将设备的工作空间映射到场景中，并选择按钮功能</translation>
    </message>
    <message>
        <source>Choose a device first: the mouse needs no calibration</source>
        <translation>请先选择设备：鼠标无需校准</translation>
    </message>
    <message>
        <source>Servo: starting</source>
        <translation>伺服：正在启动</translation>
    </message>
    <message>
        <source>Servo: %1 Hz · period %2 ms median, %3 ms p99 · %4 late · clamped: stiffness %5, force %6, rate %7 · watchdog %8 · device faults %9</source>
        <translation>伺服：%1 Hz · 周期中位数 %2 ms，p99 %3 ms · 超时 %4 次 · 限幅：刚度 %5，力 %6，变化率 %7 · 看门狗 %8 · 设备故障 %9</translation>
    </message>
    <message>
        <source>Servo: not running (the mouse moves the tool)</source>
        <translation>伺服：未运行（由鼠标移动器械）</translation>
    </message>
    <message>
        <source>Left hand</source>
        <translation>左手</translation>
    </message>
    <message>
        <source>A second instrument: a device of its own moves it, beside the one above (forceps holding the lobe while the other hand cuts)</source>
        <translation>第二件器械：由其自身的设备移动，与上方的器械并用（例如一只手用抓钳提住肝叶，另一只手切割）</translation>
    </message>
    <message>
        <source>None</source>
        <translation>无</translation>
    </message>
    <message>
        <source>Device:</source>
        <translation>设备：</translation>
    </message>
    <message>
        <source>Holds:</source>
        <translation>持有：</translation>
    </message>
    <message>
        <source>Nothing (the hand)</source>
        <translation>无（徒手）</translation>
    </message>
    <message>
        <source>Probe</source>
        <translation>探针</translation>
    </message>
    <message>
        <source>Forceps</source>
        <translation>抓钳</translation>
    </message>
    <message>
        <source>Scalpel</source>
        <translation>手术刀</translation>
    </message>
    <message>
        <source>The name Touch Setup gives the Omni in the left hand: “Left Device” for a second Omni beside the right hand&apos;s, “Default Device” for a single Omni beside the mouse</source>
        <translation>Touch Setup 中左手 Phantom Omni 的名称：与右手设备并用的第二台 Phantom Omni 为“Left Device”，与鼠标并用的单台 Phantom Omni 为“Default Device”</translation>
    </message>
    <message>
        <source>Name in Touch Setup:</source>
        <translation>Touch Setup 中的名称：</translation>
    </message>
    <message>
        <source>%1 (“%2”)</source>
        <translation>%1（“%2”）</translation>
    </message>
    <message>
        <source>Phantom Omni</source>
        <translation>Phantom Omni</translation>
    </message>
</context>
<context>
    <name>liversim::EditorGradingPanel</name>
    <message>
        <source>Metric</source>
        <translation>指标</translation>
    </message>
    <message>
        <source>Weight</source>
        <translation>权重</translation>
    </message>
    <message>
        <source>Pass if</source>
        <translation>通过条件</translation>
    </message>
    <message>
        <source>Threshold</source>
        <translation>阈值</translation>
    </message>
    <message>
        <source>The rubric: each criterion passes when its metric is at most or at least the threshold; the score is the passed criteria&apos;s share of the weights</source>
        <translation>评分标准：每项标准在其指标不超过或不低于阈值时通过；得分为已通过标准的权重占总权重的比例</translation>
    </message>
    <message>
        <source>Add criterion</source>
        <translation>添加标准</translation>
    </message>
    <message>
        <source>Remove</source>
        <translation>移除</translation>
    </message>
    <message>
        <source>Add a criterion</source>
        <translation>添加标准</translation>
    </message>
    <message>
        <source>Remove a criterion</source>
        <translation>移除标准</translation>
    </message>
    <message>
        <source>Tissue stretched past 1 + this is damaged (graded): 0.05 to 2</source>
        <translation>组织拉伸超过 1 + 此值即视为损伤（计入评分）：0.05 至 2</translation>
    </message>
    <message>
        <source>Damage in tension</source>
        <translation>拉伸损伤</translation>
    </message>
    <message>
        <source>Change the damage strain</source>
        <translation>更改损伤应变</translation>
    </message>
    <message>
        <source>Tissue squeezed below 1 − this is damaged (graded): 0.05 to 0.95</source>
        <translation>组织压缩至 1 − 此值以下即视为损伤（计入评分）：0.05 至 0.95</translation>
    </message>
    <message>
        <source>Damage in compression</source>
        <translation>压缩损伤</translation>
    </message>
    <message>
        <source>Pick on the organ</source>
        <translation>在器官上选取</translation>
    </message>
    <message>
        <source>Retraction: click where the lobe is to be grasped</source>
        <translation>牵拉：单击肝叶上要抓取的位置</translation>
    </message>
    <message>
        <source>Grasp point</source>
        <translation>抓取点</translation>
    </message>
    <message>
        <source>Retraction: how far to lift: 5 to 100 mm</source>
        <translation>牵拉：提起的高度，5 至 100 mm</translation>
    </message>
    <message>
        <source>Lift</source>
        <translation>提起高度</translation>
    </message>
    <message>
        <source>Change the lift</source>
        <translation>更改提起高度</translation>
    </message>
    <message>
        <source>(%1, %2, %3) mm</source>
        <translation>(%1, %2, %3) mm</translation>
    </message>
    <message>
        <source>retraction tasks only</source>
        <translation>仅用于牵拉任务</translation>
    </message>
    <message>
        <source>The criterion&apos;s weight in the score</source>
        <translation>该标准在得分中的权重</translation>
    </message>
    <message>
        <source>at most</source>
        <translation>不超过</translation>
    </message>
    <message>
        <source>at least</source>
        <translation>不低于</translation>
    </message>
    <message>
        <source>The threshold, in the metric&apos;s unit</source>
        <translation>阈值，单位与指标相同</translation>
    </message>
    <message>
        <source>Change a criterion&apos;s metric</source>
        <translation>更改标准的指标</translation>
    </message>
    <message>
        <source>Change a criterion&apos;s weight</source>
        <translation>更改标准的权重</translation>
    </message>
    <message>
        <source>Change a criterion&apos;s rule</source>
        <translation>更改标准的规则</translation>
    </message>
    <message>
        <source>Change a criterion&apos;s threshold</source>
        <translation>更改标准的阈值</translation>
    </message>
</context>
<context>
    <name>liversim::EditorLesionPanel</name>
    <message>
        <source>Add</source>
        <translation>添加</translation>
    </message>
    <message>
        <source>A new lesion at the organ&apos;s centre (or use Place lesion)</source>
        <translation>在器官中心新建一个病灶（或使用“放置病灶”）</translation>
    </message>
    <message>
        <source>Remove</source>
        <translation>移除</translation>
    </message>
    <message>
        <source>Remove the lesion</source>
        <translation>移除病灶</translation>
    </message>
    <message>
        <source>The lesion&apos;s name, which the task refers to</source>
        <translation>病灶名称，供任务引用</translation>
    </message>
    <message>
        <source>Name</source>
        <translation>名称</translation>
    </message>
    <message>
        <source>Rename the lesion</source>
        <translation>重命名病灶</translation>
    </message>
    <message>
        <source>The lesion&apos;s centre along the scene&apos;s %1 axis</source>
        <translation>病灶中心在场景 %1 轴上的坐标</translation>
    </message>
    <message>
        <source>The lesion&apos;s semi-axis along the scene&apos;s %1 axis (Shift-drag the lesion in the view to resize it)</source>
        <translation>病灶沿场景 %1 轴的半轴长（在视图中按住 Shift 拖动病灶可调整其大小）</translation>
    </message>
    <message>
        <source>Move the lesion</source>
        <translation>移动病灶</translation>
    </message>
    <message>
        <source>Resize the lesion</source>
        <translation>调整病灶大小</translation>
    </message>
    <message>
        <source>Centre (x, y, z)</source>
        <translation>中心 (x, y, z)</translation>
    </message>
    <message>
        <source>Semi-axes</source>
        <translation>半轴</translation>
    </message>
    <message>
        <source>Young&apos;s modulus of the lesion (instantaneous, with viscoelasticity): %1 to %2 times the parenchyma&apos;s. %3</source>
        <translation>病灶的杨氏模量（启用粘弹性时为瞬时模量）：为实质的 %1 至 %2 倍。%3</translation>
    </message>
    <message>
        <source>Stiffness E</source>
        <translation>刚度 E</translation>
    </message>
    <message>
        <source>Change the lesion&apos;s stiffness</source>
        <translation>更改病灶刚度</translation>
    </message>
    <message>
        <source>Yield limit</source>
        <translation>屈服极限</translation>
    </message>
    <message>
        <source>Change the lesion&apos;s yield limit</source>
        <translation>更改病灶屈服极限</translation>
    </message>
    <message>
        <source>Viscosity η1</source>
        <translation>粘度 η1</translation>
    </message>
    <message>
        <source>Change the lesion&apos;s viscosity</source>
        <translation>更改病灶粘度</translation>
    </message>
    <message>
        <source>Hidden from the trainee</source>
        <translation>对学员隐藏</translation>
    </message>
    <message>
        <source>Not drawn in the workstation (palpation tasks)</source>
        <translation>不在工作站中显示（触诊任务）</translation>
    </message>
    <message>
        <source>Hide the lesion</source>
        <translation>隐藏病灶</translation>
    </message>
    <message>
        <source>Show the lesion</source>
        <translation>显示病灶</translation>
    </message>
    <message>
        <source>the parenchyma&apos;s</source>
        <translation>同实质</translation>
    </message>
    <message>
        <source>Fracture toughness J</source>
        <translation>断裂韧性 J</translation>
    </message>
    <message>
        <source>Change the lesion&apos;s fracture toughness</source>
        <translation>更改病灶的断裂韧性</translation>
    </message>
    <message>
        <source>How hard the lesion is to cut: the scalpel is held back by this times the length of its edge in the lesion. </source>
        <translation>病灶的切割难度：手术刀受到的阻力为此值乘以刀刃在病灶内的长度。</translation>
    </message>
    <message>
        <source>Blade friction</source>
        <translation>刀片摩擦</translation>
    </message>
    <message>
        <source>Change the lesion&apos;s blade friction</source>
        <translation>更改病灶的刀片摩擦</translation>
    </message>
    <message>
        <source>The friction on the scalpel&apos;s sides in the lesion, per length of its edge in it. </source>
        <translation>病灶内手术刀两侧的摩擦，按其刃在病灶内的每单位长度计。</translation>
    </message>
</context>
<context>
    <name>liversim::EditorOrganPanel</name>
    <message>
        <source>Built-in liver</source>
        <translation>内置肝脏</translation>
    </message>
    <message>
        <source>Surface model (OBJ, STL, PLY, glTF, FBX, 3DS)</source>
        <translation>表面模型 (OBJ, STL, PLY, glTF, FBX, 3DS)</translation>
    </message>
    <message>
        <source>Tetrahedral mesh (.inp, .msh)</source>
        <translation>四面体网格 (.inp, .msh)</translation>
    </message>
    <message>
        <source>Organ</source>
        <translation>器官</translation>
    </message>
    <message>
        <source>Change the organ</source>
        <translation>更改器官</translation>
    </message>
    <message>
        <source>The organ&apos;s file: relative to the scenario&apos;s folder, or absolute</source>
        <translation>器官文件：相对于场景所在文件夹的路径，或绝对路径</translation>
    </message>
    <message>
        <source>Choose…</source>
        <translation>选择…</translation>
    </message>
    <message>
        <source>File</source>
        <translation>文件</translation>
    </message>
    <message>
        <source>Choose the organ&apos;s file</source>
        <translation>选择器官文件</translation>
    </message>
    <message>
        <source>The organ&apos;s file</source>
        <translation>器官文件</translation>
    </message>
    <message>
        <source>Organ files (%1);;All files (*)</source>
        <translation>器官文件 (%1);;所有文件 (*)</translation>
    </message>
    <message>
        <source>The unit of the surface model&apos;s lengths (never guessed)</source>
        <translation>表面模型的长度单位（不会自动推测）</translation>
    </message>
    <message>
        <source>Length unit</source>
        <translation>长度单位</translation>
    </message>
    <message>
        <source>Change the organ&apos;s unit</source>
        <translation>更改器官单位</translation>
    </message>
    <message>
        <source>Elements of the organ&apos;s mesh: 1000 to 50000 (more is more accurate and slower: see the cost in Tissue and effects)</source>
        <translation>器官网格的单元数：1000 至 50000（越多越精确，也越慢：计算开销见“组织与效应”）</translation>
    </message>
    <message>
        <source>Elements</source>
        <translation>单元数</translation>
    </message>
    <message>
        <source>Change the element count</source>
        <translation>更改单元数</translation>
    </message>
    <message>
        <source>A node set of the mesh file held fixed (empty: none)</source>
        <translation>网格文件中保持固定的节点集（留空：无）</translation>
    </message>
    <message>
        <source>Fixed node set</source>
        <translation>固定节点集</translation>
    </message>
    <message>
        <source>Change the fixed node set</source>
        <translation>更改固定节点集</translation>
    </message>
    <message>
        <source>Change the integrator</source>
        <translation>更改时间积分器</translation>
    </message>
</context>
<context>
    <name>liversim::EditorTaskPanel</name>
    <message>
        <source>Title</source>
        <translation>标题</translation>
    </message>
    <message>
        <source>Change the title</source>
        <translation>更改标题</translation>
    </message>
    <message>
        <source>Description</source>
        <translation>描述</translation>
    </message>
    <message>
        <source>Change the description</source>
        <translation>更改描述</translation>
    </message>
    <message>
        <source>Palpate a hidden lesion</source>
        <translation>触诊隐藏病灶</translation>
    </message>
    <message>
        <source>Retract a lobe</source>
        <translation>牵拉肝叶</translation>
    </message>
    <message>
        <source>Resect a lesion</source>
        <translation>切除病灶</translation>
    </message>
    <message>
        <source>Task</source>
        <translation>任务</translation>
    </message>
    <message>
        <source>Change the task</source>
        <translation>更改任务</translation>
    </message>
    <message>
        <source>Shown to the trainee</source>
        <translation>向学员显示</translation>
    </message>
    <message>
        <source>Instructions</source>
        <translation>任务说明</translation>
    </message>
    <message>
        <source>Change the instructions</source>
        <translation>更改任务说明</translation>
    </message>
    <message>
        <source>The time the trainee has: 10 s to 2 h</source>
        <translation>学员可用的时间：10 s 至 2 h</translation>
    </message>
    <message>
        <source>Time limit</source>
        <translation>时限</translation>
    </message>
    <message>
        <source>Change the time limit</source>
        <translation>更改时限</translation>
    </message>
    <message>
        <source>The lesion to find or to resect</source>
        <translation>要查找或切除的病灶</translation>
    </message>
    <message>
        <source>Lesion</source>
        <translation>病灶</translation>
    </message>
    <message>
        <source>Choose the task&apos;s lesion</source>
        <translation>选择任务的病灶</translation>
    </message>
    <message>
        <source>Resection: the least distance from the cut to the lesion</source>
        <translation>切除：切口与病灶之间的最小距离</translation>
    </message>
    <message>
        <source>Margin</source>
        <translation>切缘</translation>
    </message>
    <message>
        <source>Change the margin</source>
        <translation>更改切缘</translation>
    </message>
    <message>
        <source>Clear</source>
        <translation>清除</translation>
    </message>
    <message>
        <source>Clear the planned plane</source>
        <translation>清除计划平面</translation>
    </message>
    <message>
        <source>Planned plane</source>
        <translation>计划平面</translation>
    </message>
    <message>
        <source>Allow a tool</source>
        <translation>允许使用器械</translation>
    </message>
    <message>
        <source>Withdraw a tool</source>
        <translation>禁用器械</translation>
    </message>
    <message>
        <source>Tools</source>
        <translation>器械</translation>
    </message>
    <message>
        <source>A force on the tissue above this is excessive (graded)</source>
        <translation>作用于组织的力超过此值即为过大（计入评分）</translation>
    </message>
    <message>
        <source>Safe force</source>
        <translation>安全力</translation>
    </message>
    <message>
        <source>Change the safe force</source>
        <translation>更改安全力</translation>
    </message>
    <message>
        <source>through (%1, %2, %3) mm, normal (%4, %5, %6)</source>
        <translation>经过 (%1, %2, %3) mm，法向 (%4, %5, %6)</translation>
    </message>
    <message>
        <source>none: draw it across the organ (Draw plane)</source>
        <translation>无：请在器官上绘制（“绘制平面”）</translation>
    </message>
    <message>
        <source>resection tasks only</source>
        <translation>仅用于切除任务</translation>
    </message>
</context>
<context>
    <name>liversim::EditorTissuePanel</name>
    <message>
        <source>Parenchyma E</source>
        <translation>实质 E</translation>
    </message>
    <message>
        <source>Change the parenchyma&apos;s stiffness</source>
        <translation>更改实质刚度</translation>
    </message>
    <message>
        <source>Poisson&apos;s ratio ν</source>
        <translation>泊松比 ν</translation>
    </message>
    <message>
        <source>Change Poisson&apos;s ratio</source>
        <translation>更改泊松比</translation>
    </message>
    <message>
        <source>Effects simulated (an effect off costs nothing)</source>
        <translation>仿真的效应（关闭的效应不产生计算开销）</translation>
    </message>
    <message>
        <source>Near-incompressibility (averaged pressure)</source>
        <translation>近不可压缩性（平均压力）</translation>
    </message>
    <message>
        <source>Viscoelasticity (relaxation, creep)</source>
        <translation>粘弹性（松弛、蠕变）</translation>
    </message>
    <message>
        <source>Viscoplasticity above the yield limit</source>
        <translation>超过屈服极限后的粘塑性</translation>
    </message>
    <message>
        <source>Fibre anisotropy (HGO)</source>
        <translation>纤维各向异性 (HGO)</translation>
    </message>
    <message>
        <source>Switch an effect on</source>
        <translation>开启效应</translation>
    </message>
    <message>
        <source>Switch an effect off</source>
        <translation>关闭效应</translation>
    </message>
    <message>
        <source>Steps per second of this scenario on this machine, measured now: its model stepped for half a second under a 0.5 N pull</source>
        <translation>此场景在本机上每秒的步数，即时测量：模型在 0.5 N 拉力下推进半秒</translation>
    </message>
    <message>
        <source>Laws of the effects</source>
        <translation>效应的本构参数</translation>
    </message>
    <message>
        <source>Change %1</source>
        <translation>更改%1</translation>
    </message>
    <message>
        <source>Maxwell arm E1</source>
        <translation>Maxwell 支路 E1</translation>
    </message>
    <message>
        <source> E2 = E − E1 follows, so that E stays the parenchyma&apos;s.</source>
        <translation> E2 = E − E1 随之确定，使 E 保持为实质的值。</translation>
    </message>
    <message>
        <source>Maxwell arm η1</source>
        <translation>Maxwell 支路 η1</translation>
    </message>
    <message>
        <source>Yield limit σs</source>
        <translation>屈服极限 σs</translation>
    </message>
    <message>
        <source>Viscoplastic η2</source>
        <translation>粘塑性 η2</translation>
    </message>
    <message>
        <source>Creep index n</source>
        <translation>蠕变指数 n</translation>
    </message>
    <message>
        <source>Fibre k1</source>
        <translation>纤维 k1</translation>
    </message>
    <message>
        <source>Fibre k2</source>
        <translation>纤维 k2</translation>
    </message>
    <message>
        <source>Fibre direction</source>
        <translation>纤维方向</translation>
    </message>
    <message>
        <source>The fibres&apos; reference direction (normalised on saving)</source>
        <translation>纤维的参考方向（保存时归一化）</translation>
    </message>
    <message>
        <source>Change the fibre direction</source>
        <translation>更改纤维方向</translation>
    </message>
    <message>
        <source>Across the view</source>
        <translation>沿视图横向</translation>
    </message>
    <message>
        <source>Fibres along the screen&apos;s horizontal, as the organ is seen now</source>
        <translation>按器官当前的视角，使纤维沿屏幕水平方向</translation>
    </message>
    <message>
        <source>Set the fibre direction</source>
        <translation>设置纤维方向</translation>
    </message>
    <message>
        <source>Fixed regions</source>
        <translation>固定区域</translation>
    </message>
    <message>
        <source>Radius of the painting brush (Paint fixed)</source>
        <translation>涂刷画笔的半径（涂刷固定区）</translation>
    </message>
    <message>
        <source>Brush</source>
        <translation>画笔</translation>
    </message>
    <message>
        <source>Clear painted</source>
        <translation>清除涂刷</translation>
    </message>
    <message>
        <source>Clear the painted fixed regions</source>
        <translation>清除涂刷的固定区域</translation>
    </message>
    <message>
        <source>Painted</source>
        <translation>已涂刷</translation>
    </message>
    <message>
        <source>Coronary ligament (built-in liver)</source>
        <translation>冠状韧带（内置肝脏）</translation>
    </message>
    <message>
        <source>Change the ligament</source>
        <translation>更改韧带</translation>
    </message>
    <message numerus="yes">
        <source>%n ball(s)</source>
        <translation>
            <numerusform>%n 个球形区域</numerusform>
        </translation>
    </message>
    <message>
        <source>Supine: toward the back (−z)</source>
        <translation>仰卧位：朝向背侧（−z）</translation>
    </message>
    <message>
        <source>Upright: toward the feet (−y)</source>
        <translation>直立位：朝向足侧（−y）</translation>
    </message>
    <message>
        <source>Prone: toward the front (+z)</source>
        <translation>俯卧位：朝向腹侧（+z）</translation>
    </message>
    <message>
        <source>Gravity (the organ&apos;s weight)</source>
        <translation>重力（器官自重）</translation>
    </message>
    <message>
        <source>Switch gravity on</source>
        <translation>开启重力</translation>
    </message>
    <message>
        <source>Switch gravity off</source>
        <translation>关闭重力</translation>
    </message>
    <message>
        <source>Which way is down: the patient&apos;s position on the table</source>
        <translation>向下的方向：患者在手术台上的体位</translation>
    </message>
    <message>
        <source>As the file sets it</source>
        <translation>按文件设定</translation>
    </message>
    <message>
        <source>Down</source>
        <translation>向下</translation>
    </message>
    <message>
        <source>Change gravity&apos;s direction</source>
        <translation>更改重力方向</translation>
    </message>
    <message>
        <source>Gravity&apos;s strength g: 9.81 m/s² on Earth</source>
        <translation>重力加速度 g：地球上为 9.81 m/s²</translation>
    </message>
    <message>
        <source>g</source>
        <translation>g</translation>
    </message>
    <message>
        <source>Change gravity&apos;s strength</source>
        <translation>更改重力大小</translation>
    </message>
    <message>
        <source>The energy to cut new surface: the scalpel is held back by it times the length of its edge in the tissue, and breaks in when pressed that hard. </source>
        <translation>切出新表面所需的能量：手术刀受到的阻力为此值乘以刀刃在组织内的长度，按压达到该力时刀刃切入。</translation>
    </message>
    <message>
        <source>Fracture toughness J</source>
        <translation>断裂韧性 J</translation>
    </message>
    <message>
        <source>Change the fracture toughness</source>
        <translation>更改断裂韧性</translation>
    </message>
    <message>
        <source>The friction on the scalpel&apos;s sides: it is held back by this times the length of its edge in the tissue, whichever way it moves while it cuts (assumed: 70 N/m). </source>
        <translation>手术刀两侧的摩擦：切割时无论朝哪个方向移动，它所受的阻力为此值乘以刃在组织内的长度（假定值：70 N/m）。</translation>
    </message>
    <message>
        <source>Blade friction</source>
        <translation>刀片摩擦</translation>
    </message>
    <message>
        <source>Change the blade friction</source>
        <translation>更改刀片摩擦</translation>
    </message>
</context>
<context>
    <name>liversim::ForceTrace</name>
    <message>
        <source>Force on the tool over the last %1 s</source>
        <translation>最近 %1 s 内器械受力</translation>
    </message>
    <message>
        <source>%1 N</source>
        <translation>%1 N</translation>
    </message>
</context>
<context>
    <name>liversim::InstructorLoginDialog</name>
    <message>
        <source>Instructor Log-in</source>
        <translation>教师登录</translation>
    </message>
    <message>
        <source>First Instructor Account</source>
        <translation>第一个教师账户</translation>
    </message>
    <message>
        <source>Add an Instructor Account</source>
        <translation>添加教师账户</translation>
    </message>
    <message>
        <source>Instructor mode changes the tissue, authors scenarios and grades sessions. Log in with your instructor account.</source>
        <translation>教师模式可修改组织、编写场景并为会话评分。请用您的教师账户登录。</translation>
    </message>
    <message>
        <source>This workstation has no instructor account yet. Set up the first one: its name and a password of at least %1 characters. Further accounts can then be added only by an instructor who has logged in.</source>
        <translation>此工作站尚无教师账户。请设置第一个账户：名称及至少 %1 个字符的密码。之后只有已登录的教师才能添加更多账户。</translation>
    </message>
    <message>
        <source>A new instructor account: its name and a password of at least %1 characters.</source>
        <translation>新的教师账户：名称及至少 %1 个字符的密码。</translation>
    </message>
    <message>
        <source>Name:</source>
        <translation>名称：</translation>
    </message>
    <message>
        <source>Password:</source>
        <translation>密码：</translation>
    </message>
    <message>
        <source>Password again:</source>
        <translation>再次输入密码：</translation>
    </message>
    <message>
        <source>Create Account</source>
        <translation>创建账户</translation>
    </message>
    <message>
        <source>Log In</source>
        <translation>登录</translation>
    </message>
    <message>
        <source>Enter the instructor&apos;s name.</source>
        <translation>请输入教师的名称。</translation>
    </message>
    <message>
        <source>Enter the password.</source>
        <translation>请输入密码。</translation>
    </message>
    <message>
        <source>The two passwords differ: type the same password twice.</source>
        <translation>两次输入的密码不同：请两次输入相同的密码。</translation>
    </message>
</context>
<context>
    <name>liversim::MainWindow</name>
    <message>
        <source>Scenario</source>
        <translation>场景</translation>
    </message>
    <message>
        <source>Accuracy</source>
        <translation>精度</translation>
    </message>
    <message>
        <source>Tool</source>
        <translation>器械</translation>
    </message>
    <message>
        <source>Device</source>
        <translation>设备</translation>
    </message>
    <message>
        <source>Drag the liver with the left mouse button; drag the background to turn the view, wheel to zoom.</source>
        <translation>按住鼠标左键拖动肝脏；拖动背景可旋转视图，滚动滚轮可缩放。</translation>
    </message>
    <message>
        <source>Building the scene of %1…</source>
        <translation>正在构建 %1 的场景…</translation>
    </message>
    <message>
        <source>Building the scene of %1: meshing the organ, attempt %2 of at most %3 (elements of %4 mm)…</source>
        <translation>正在构建 %1 的场景：正在为器官划分网格，第 %2 次尝试（最多 %3 次，单元尺寸 %4 mm）…</translation>
    </message>
    <message>
        <source>Building the scene of %1: attempt %2 made %3 elements…</source>
        <translation>正在构建 %1 的场景：第 %2 次尝试生成了 %3 个单元…</translation>
    </message>
    <message>
        <source>Opened %1.</source>
        <translation>已打开 %1。</translation>
    </message>
    <message>
        <source>“%1” (from the editor, not saved)</source>
        <translation>“%1”（来自编辑器，未保存）</translation>
    </message>
    <message>
        <source>Cannot open the scenario %1:
%2
The scene that was running goes on.</source>
        <translation>无法打开场景 %1：
%2
原先运行的场景将继续运行。</translation>
    </message>
    <message>
        <source>Cannot open the scenario %1.</source>
        <translation>无法打开场景 %1。</translation>
    </message>
    <message>
        <source>Cannot open the scenario</source>
        <translation>无法打开场景</translation>
    </message>
    <message>
        <source>LiverSim — %1</source>
        <translation>LiverSim — %1</translation>
    </message>
    <message>
        <source>&amp;File</source>
        <translation>文件(&amp;F)</translation>
    </message>
    <message>
        <source>&amp;Open Scenario…</source>
        <translation>打开场景(&amp;O)…</translation>
    </message>
    <message>
        <source>Open a scenario</source>
        <translation>打开场景</translation>
    </message>
    <message>
        <source>LiverSim scenarios (*.json);;All files (*)</source>
        <translation>LiverSim 场景 (*.json);;所有文件 (*)</translation>
    </message>
    <message>
        <source>Open &amp;Recent</source>
        <translation>最近打开(&amp;R)</translation>
    </message>
    <message>
        <source>Scenario &amp;Editor…</source>
        <translation>场景编辑器(&amp;E)…</translation>
    </message>
    <message>
        <source>Instructors: author the scenario shown, or a new one</source>
        <translation>供教员使用：编辑当前显示的场景，或新建场景</translation>
    </message>
    <message>
        <source>&amp;Quit</source>
        <translation>退出(&amp;Q)</translation>
    </message>
    <message>
        <source>&amp;Session</source>
        <translation>训练(&amp;S)</translation>
    </message>
    <message>
        <source>&amp;Mark the Lesion Here</source>
        <translation>在此标记病灶(&amp;M)</translation>
    </message>
    <message>
        <source>&amp;Review Sessions…</source>
        <translation>审阅训练记录(&amp;R)…</translation>
    </message>
    <message>
        <source>My &amp;Sessions…</source>
        <translation>我的训练记录(&amp;S)…</translation>
    </message>
    <message>
        <source>Palpation: mark the point of the liver under the tool as where the lesion is (graded at the session&apos;s end)</source>
        <translation>触诊：将器械下方的肝脏位置标记为病灶所在处（训练结束时评分）</translation>
    </message>
    <message>
        <source>A scene is still being built; try the scenario after it.</source>
        <translation>仍在构建场景；请在构建完成后再试运行该场景。</translation>
    </message>
    <message>
        <source>A scene is still being built; open the scenario after it.</source>
        <translation>仍在构建场景；请在构建完成后再打开该场景。</translation>
    </message>
    <message>
        <source>The liver was cut while the integrator changed; apply it again.</source>
        <translation>更换时间积分器期间肝脏被切割；请重新应用。</translation>
    </message>
    <message>
        <source>%1 fps | %2 steps/s | real-time factor %3 | step %4 ms</source>
        <translation>%1 帧/秒 | %2 步/秒 | 实时因子 %3 | 步长 %4 ms</translation>
    </message>
    <message>
        <source> | slower than real time</source>
        <translation> | 慢于实时</translation>
    </message>
    <message>
        <source> | </source>
        <translation> | </translation>
    </message>
    <message>
        <source>Simulation halted: %1; every retry with shorter steps failed. Apply a setting in the Accuracy panel (another integrator or a shorter step) to go on from the last good state. | </source>
        <translation>仿真已停止：%1；以更短步长进行的所有重试均失败。请在“精度”面板中应用新设置（更换时间积分器或缩短步长），以从最后一个正常状态继续。 | </translation>
    </message>
    <message>
        <source> | recovered %1 times, refused %2 inputs (last: %3)</source>
        <translation> | 已恢复 %1 次，拒绝输入 %2 次（最近一次：%3）</translation>
    </message>
    <message>
        <source> | energy books: the scheme is creating energy (choose a shorter step or an implicit scheme)</source>
        <translation> | 能量核算：积分格式正在凭空产生能量（请选用更短的步长或隐式格式）</translation>
    </message>
    <message>
        <source> | pulling %1 N</source>
        <translation> | 拉力 %1 N</translation>
    </message>
    <message>
        <source> | resected %1 mL</source>
        <translation> | 已切除 %1 mL</translation>
    </message>
    <message>
        <source>no problem</source>
        <translation>无问题</translation>
    </message>
    <message>
        <source>a tool input was not a number</source>
        <translation>器械输入不是有效数值</translation>
    </message>
    <message>
        <source>a node position became not a number</source>
        <translation>某节点位置变为非数值</translation>
    </message>
    <message>
        <source>a node velocity became not a number</source>
        <translation>某节点速度变为非数值</translation>
    </message>
    <message>
        <source>a node moved implausibly fast</source>
        <translation>某节点移动速度异常过快</translation>
    </message>
    <message>
        <source>a node gained more energy than the tools put in</source>
        <translation>某节点获得的能量超过器械输入的能量</translation>
    </message>
    <message>
        <source>an implicit step did not converge</source>
        <translation>隐式步未收敛</translation>
    </message>
    <message>
        <source>the step fell below a thousandth of its value at rest (tissue drawn or crushed past what the step can follow)</source>
        <translation>步长降至静止时的千分之一以下（组织被拉伸或挤压到步长无法跟随的程度）</translation>
    </message>
    <message>
        <source>unknown problem</source>
        <translation>未知问题</translation>
    </message>
    <message>
        <source>n/a</source>
        <translation>无</translation>
    </message>
    <message>
        <source>&lt; 1 pm</source>
        <translation>&lt; 1 pm</translation>
    </message>
    <message>
        <source>≈ %1 pm</source>
        <translation>≈ %1 pm</translation>
    </message>
    <message>
        <source>≈ %1 nm</source>
        <translation>≈ %1 nm</translation>
    </message>
    <message>
        <source>≈ %1 µm</source>
        <translation>≈ %1 µm</translation>
    </message>
    <message>
        <source>≈ %1 mm</source>
        <translation>≈ %1 mm</translation>
    </message>
    <message>
        <source>%1 · error %2</source>
        <translation>%1 · 误差 %2</translation>
    </message>
    <message>
        <source> · %1 ms wall per ms simulated · %2 force evaluations per ms simulated</source>
        <translation> · 每仿真 1 ms 耗时 %1 ms · 每仿真 1 ms 计算力 %2 次</translation>
    </message>
    <message>
        <source> · stability-limited</source>
        <translation> · 受稳定性限制</translation>
    </message>
    <message>
        <source>Sessions are not recorded: %1</source>
        <translation>无法记录训练：%1</translation>
    </message>
    <message>
        <source>There is no sessions database.</source>
        <translation>没有训练记录数据库。</translation>
    </message>
    <message>
        <source>Trainee</source>
        <translation>学员</translation>
    </message>
    <message>
        <source>Marks are kept with a recorded session: put a tool on the liver first.</source>
        <translation>标记随训练记录保存：请先将器械放到肝脏上。</translation>
    </message>
    <message>
        <source>Marks are kept with a recorded session, and there is no sessions database.</source>
        <translation>标记随训练记录保存，但没有训练记录数据库。</translation>
    </message>
    <message>
        <source>Hold a tool over the place to mark.</source>
        <translation>请将器械停在要标记的位置上。</translation>
    </message>
    <message>
        <source>Marked the lesion at (%1, %2, %3) mm.</source>
        <translation>已在 (%1, %2, %3) mm 处标记病灶。</translation>
    </message>
    <message>
        <source>The session was not saved whole: %1</source>
        <translation>训练记录未完整保存：%1</translation>
    </message>
    <message>
        <source>The session&apos;s metrics were not stored: %1</source>
        <translation>训练记录的指标未保存：%1</translation>
    </message>
    <message>
        <source>Se&amp;ttings</source>
        <translation>设置(&amp;T)</translation>
    </message>
    <message>
        <source>&amp;Language</source>
        <translation>语言(&amp;L)</translation>
    </message>
    <message>
        <source>LiverSim will use this language when it starts again.</source>
        <translation>LiverSim 将在下次启动时使用此语言。</translation>
    </message>
    <message>
        <source>The System&apos;s Language</source>
        <translation>跟随系统语言</translation>
    </message>
    <message>
        <source>free practice, %1 elements</source>
        <translation>自由练习，%1 个单元</translation>
    </message>
    <message>
        <source>The tool models could not be read, so the tools are drawn as simple shapes: %1</source>
        <translation>无法读取器械模型，器械将以简单形状显示：%1</translation>
    </message>
    <message>
        <source>&amp;View</source>
        <translation>视图(&amp;V)</translation>
    </message>
    <message>
        <source>&amp;See-through Liver</source>
        <translation>透视肝脏(&amp;S)</translation>
    </message>
    <message>
        <source>Show the liver translucent, with the lesions inside it</source>
        <translation>以半透明方式显示肝脏及其内部病灶</translation>
    </message>
    <message>
        <source>a scene or an integrator change is being built; enter the value again after it.</source>
        <translation>正在构建场景或更换积分器；请在其完成后重新输入该值。</translation>
    </message>
    <message>
        <source>Material</source>
        <translation>材料</translation>
    </message>
    <message>
        <source>Cancel</source>
        <translation>取消</translation>
    </message>
    <message>
        <source>Stop building the scene; the scene that is running goes on</source>
        <translation>停止构建场景；正在运行的场景继续运行</translation>
    </message>
    <message>
        <source>Opening %1 was cancelled; the scene that was running goes on.</source>
        <translation>已取消打开 %1；原来运行的场景继续运行。</translation>
    </message>
    <message>
        <source>Cancelling…</source>
        <translation>正在取消…</translation>
    </message>
    <message>
        <source>&amp;Ambient Occlusion</source>
        <translation>环境光遮蔽(&amp;A)</translation>
    </message>
    <message>
        <source>Darken creases and cut edges by their ambient occlusion (costs frame rate: docs/rendering-performance.md)</source>
        <translation>按环境光遮蔽加深褶皱和切口边缘（会降低帧率：docs/rendering-performance.md）</translation>
    </message>
    <message>
        <source>&amp;Panels</source>
        <translation>面板(&amp;P)</translation>
    </message>
    <message>
        <source>Instructors: review and grade every trainee&apos;s sessions</source>
        <translation>教师：查看并评分所有学员的训练记录</translation>
    </message>
    <message>
        <source>&amp;Instructor Mode</source>
        <translation>教师模式(&amp;I)</translation>
    </message>
    <message>
        <source>Main Toolbar</source>
        <translation>主工具栏</translation>
    </message>
    <message>
        <source>%1 (%2)</source>
        <translation>%1（%2）</translation>
    </message>
    <message>
        <source>The liver was cut while the tissue changed; enter it again.</source>
        <translation>修改组织参数期间肝脏被切开；请重新输入。</translation>
    </message>
    <message>
        <source>Not applied: a model is being built. Try again when it is done.</source>
        <translation>未应用：正在构建模型。请在完成后重试。</translation>
    </message>
    <message>
        <source>Instructor accounts are kept in the sessions database, which cannot be used: %1</source>
        <translation>教师账户保存在会话数据库中，但该数据库无法使用：%1</translation>
    </message>
    <message>
        <source>there is none</source>
        <translation>没有数据库</translation>
    </message>
    <message>
        <source>Cannot log in: %1</source>
        <translation>无法登录：%1</translation>
    </message>
    <message>
        <source>Cannot set up the account: %1</source>
        <translation>无法设置账户：%1</translation>
    </message>
    <message>
        <source>Wrong name or password.</source>
        <translation>名称或密码错误。</translation>
    </message>
    <message>
        <source>Logged in as %1 (instructor).</source>
        <translation>已以 %1（教师）身份登录。</translation>
    </message>
    <message>
        <source>Only an instructor who has logged in can add instructor accounts.</source>
        <translation>只有已登录的教师才能添加教师账户。</translation>
    </message>
    <message>
        <source>The account was not added: %1</source>
        <translation>账户未添加：%1</translation>
    </message>
    <message>
        <source>Instructor account %1 added.</source>
        <translation>已添加教师账户 %1。</translation>
    </message>
    <message>
        <source>Instructor mode, after a log-in: change the tissue, author scenarios, review and grade every trainee&apos;s sessions</source>
        <translation>教师模式（需登录）：修改组织、编写场景、查看并评分每位学员的会话</translation>
    </message>
    <message>
        <source>&amp;Add Instructor Account…</source>
        <translation>添加教师账户(&amp;A)…</translation>
    </message>
    <message>
        <source>Reviewing every trainee&apos;s sessions is for instructors: log in first (Settings ▸ Instructor Mode).</source>
        <translation>查看所有学员的会话仅限教师：请先登录（设置 ▸ 教师模式）。</translation>
    </message>
    <message>
        <source>Authoring scenarios is for instructors: log in first (Settings ▸ Instructor Mode).</source>
        <translation>编写场景仅限教师：请先登录（设置 ▸ 教师模式）。</translation>
    </message>
    <message>
        <source>Changing the tissue is for instructors: log in first (Settings ▸ Instructor Mode).</source>
        <translation>修改组织仅限教师：请先登录（设置 ▸ 教师模式）。</translation>
    </message>
    <message>
        <source>Recording stopped: this session is no longer being saved (what was saved before is kept). %1</source>
        <translation>录制已停止：此会话不再保存（之前已保存的内容会保留）。%1</translation>
    </message>
    <message>
        <source>Review Sessions on the Ser&amp;ver…</source>
        <translation>在服务器上评阅训练(&amp;V)…</translation>
    </message>
    <message>
        <source>Log in to the training centre&apos;s server</source>
        <translation>登录培训中心服务器</translation>
    </message>
    <message>
        <source>Instructors: review and grade the sessions of every workstation on the training centre&apos;s server</source>
        <translation>教员：在培训中心服务器上评阅并评分所有工作站的训练</translation>
    </message>
    <message>
        <source>&amp;Training Centre Server…</source>
        <translation>培训中心服务器(&amp;T)…</translation>
    </message>
    <message>
        <source>Upload finished sessions to the training centre&apos;s server and pull its scenarios</source>
        <translation>将已结束的训练上传到培训中心服务器，并获取其发布的情景</translation>
    </message>
    <message>
        <source>a scene or another change of the model is being built; switch gravity again after it.</source>
        <translation>正在构建场景或模型的其他更改；请在其完成后再切换重力。</translation>
    </message>
    <message>
        <source>Gravity is the scenario&apos;s: an instructor can switch it (Settings ▸ Instructor Mode).</source>
        <translation>重力由场景设定：教员可以切换它（设置 ▸ 教员模式）。</translation>
    </message>
    <message>
        <source>The liver was cut while gravity was switched; switch it again.</source>
        <translation>切换重力时肝脏被切割了；请再次切换。</translation>
    </message>
    <message>
        <source>Remove &amp;Specimen</source>
        <translation>取出标本(&amp;S)</translation>
    </message>
    <message>
        <source>There is no specimen to remove: no piece has been cut free.</source>
        <translation>没有可取出的标本：尚无切下的组织块。</translation>
    </message>
    <message numerus="yes">
        <source>Took %n specimen(s) out of the field.</source>
        <translation>
            <numerusform>已从术野取出 %n 个标本。</numerusform>
        </translation>
    </message>
    <message>
        <source>Take the pieces cut free out of the field; they are kept as the session&apos;s specimen</source>
        <translation>将切下的组织块移出术野；它们作为本次训练的标本保存</translation>
    </message>
    <message numerus="yes">
        <source> | %n piece(s) cut free: lift out or Session ▸ Remove Specimen</source>
        <translation>
            <numerusform> | 已切下 %n 块组织：请取出，或使用 训练 ▸ 取出标本</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source> | %n specimen(s) taken out</source>
        <translation>
            <numerusform> | 已取出 %n 个标本</numerusform>
        </translation>
    </message>
</context>
<context>
    <name>liversim::MaterialPanel</name>
    <message>
        <source> kPa</source>
        <translation> kPa</translation>
    </message>
    <message>
        <source>Young&apos;s modulus E</source>
        <translation>杨氏模量 E</translation>
    </message>
    <message>
        <source>Poisson&apos;s ratio ν</source>
        <translation>泊松比 ν</translation>
    </message>
    <message>
        <source> kg/m³</source>
        <translation> kg/m³</translation>
    </message>
    <message>
        <source>Density ρ</source>
        <translation>密度 ρ</translation>
    </message>
    <message>
        <source> Pa</source>
        <translation> Pa</translation>
    </message>
    <message>
        <source>Maxwell arm E1</source>
        <translation>Maxwell 支路 E1</translation>
    </message>
    <message>
        <source> Pa·s</source>
        <translation> Pa·s</translation>
    </message>
    <message>
        <source>Maxwell arm η1</source>
        <translation>Maxwell 支路 η1</translation>
    </message>
    <message>
        <source>Yield limit σs</source>
        <translation>屈服极限 σs</translation>
    </message>
    <message>
        <source> Pa·sⁿ</source>
        <translation> Pa·sⁿ</translation>
    </message>
    <message>
        <source>Viscoplastic η2</source>
        <translation>粘塑性 η2</translation>
    </message>
    <message>
        <source>Creep index n</source>
        <translation>蠕变指数 n</translation>
    </message>
    <message>
        <source>Fibre k1</source>
        <translation>纤维 k1</translation>
    </message>
    <message>
        <source>Fibre k2</source>
        <translation>纤维 k2</translation>
    </message>
    <message>
        <source>Trainee mode: the tissue is the scenario&apos;s. An instructor can change it in instructor mode (Settings menu).</source>
        <translation>学员模式：组织参数由场景决定。教师可在教师模式（设置菜单）中修改。</translation>
    </message>
    <message>
        <source>A value entered is applied to the running liver at once; it goes on from where it is. The laws of effects the scene leaves off are not simulated and not shown.</source>
        <translation>输入的值立即作用于正在运行的肝脏，并从当前状态继续。场景未启用的效应既不模拟也不显示。</translation>
    </message>
    <message>
        <source>In use. Effects left off (not simulated): %1.</source>
        <translation>正在使用。未启用（不模拟）的效应：%1。</translation>
    </message>
    <message>
        <source>viscoelasticity</source>
        <translation>粘弹性</translation>
    </message>
    <message>
        <source>viscoplasticity</source>
        <translation>粘塑性</translation>
    </message>
    <message>
        <source>fibres</source>
        <translation>纤维</translation>
    </message>
    <message>
        <source>none</source>
        <translation>无</translation>
    </message>
    <message>
        <source>, </source>
        <translation>、</translation>
    </message>
    <message>
        <source>E2 = E − E1 = %1 Pa; relaxation time τ = η1/E1 = %2 s</source>
        <translation>E2 = E − E1 = %1 Pa；松弛时间 τ = η1/E1 = %2 s</translation>
    </message>
    <message>
        <source>Applying the new tissue to the running liver…</source>
        <translation>正在将新的组织参数应用到运行中的肝脏…</translation>
    </message>
    <message>
        <source>Not applied: %1</source>
        <translation>未应用：%1</translation>
    </message>
    <message>
        <source>%1: %2 to %3%4</source>
        <translation>%1：%2 至 %3%4</translation>
    </message>
    <message>
        <source>. E2 = E − E1 follows.</source>
        <translation>。E2 = E − E1 随之确定。</translation>
    </message>
    <message>
        <source>The organ&apos;s weight pulls it onto its bed</source>
        <translation>器官的重量将其压在其支撑床上</translation>
    </message>
    <message>
        <source>Gravity</source>
        <translation>重力</translation>
    </message>
    <message>
        <source>g = %1 m/s² toward (%2, %3, %4), the scene&apos;s axes; it rests on a bed shaped as its underside, and on a tray around it</source>
        <translation>g = %1 m/s²，方向 (%2, %3, %4)（场景坐标轴）；器官躺在与其底面形状相同的支撑床上，周围有托盘</translation>
    </message>
    <message>
        <source>gravity</source>
        <translation>重力</translation>
    </message>
    <message>
        <source>Switching gravity on…</source>
        <translation>正在开启重力…</translation>
    </message>
    <message>
        <source>Switching gravity off…</source>
        <translation>正在关闭重力…</translation>
    </message>
    <message>
        <source> J/m²</source>
        <translation> J/m²</translation>
    </message>
    <message>
        <source>Fracture toughness J</source>
        <translation>断裂韧性 J</translation>
    </message>
    <message>
        <source>. What holds the scalpel back as it cuts.</source>
        <translation>。切割时阻碍手术刀的正是它。</translation>
    </message>
    <message>
        <source> N/m</source>
        <translation> N/m</translation>
    </message>
    <message>
        <source>Blade friction</source>
        <translation>刀片摩擦</translation>
    </message>
    <message>
        <source>. The friction on the scalpel&apos;s sides as it cuts.</source>
        <translation>。切割时手术刀两侧的摩擦。</translation>
    </message>
</context>
<context>
    <name>liversim::ScenarioDocument</name>
    <message>
        <source>New scenario</source>
        <translation>新场景</translation>
    </message>
</context>
<context>
    <name>liversim::ScenarioEditor</name>
    <message>
        <source>Lesions</source>
        <translation>病灶</translation>
    </message>
    <message>
        <source>Task</source>
        <translation>任务</translation>
    </message>
    <message>
        <source>Tissue and effects</source>
        <translation>组织与效应</translation>
    </message>
    <message>
        <source>Organ and accuracy</source>
        <translation>器官与精度</translation>
    </message>
    <message>
        <source>Grading</source>
        <translation>评分</translation>
    </message>
    <message>
        <source>&amp;File</source>
        <translation>文件(&amp;F)</translation>
    </message>
    <message>
        <source>Editor</source>
        <translation>编辑器</translation>
    </message>
    <message>
        <source>&amp;New Scenario</source>
        <translation>新建场景(&amp;N)</translation>
    </message>
    <message>
        <source>&amp;Open…</source>
        <translation>打开(&amp;O)…</translation>
    </message>
    <message>
        <source>Open a scenario</source>
        <translation>打开场景</translation>
    </message>
    <message>
        <source>LiverSim scenarios (*.json);;All files (*)</source>
        <translation>LiverSim 场景 (*.json);;所有文件 (*)</translation>
    </message>
    <message>
        <source>Open &amp;Recent</source>
        <translation>最近打开(&amp;R)</translation>
    </message>
    <message>
        <source>&amp;Save</source>
        <translation>保存(&amp;S)</translation>
    </message>
    <message>
        <source>Save &amp;As…</source>
        <translation>另存为(&amp;A)…</translation>
    </message>
    <message>
        <source>Save the scenario</source>
        <translation>保存场景</translation>
    </message>
    <message>
        <source>LiverSim scenarios (*.json)</source>
        <translation>LiverSim 场景 (*.json)</translation>
    </message>
    <message>
        <source>&amp;Close</source>
        <translation>关闭(&amp;C)</translation>
    </message>
    <message>
        <source>&amp;Edit</source>
        <translation>编辑(&amp;E)</translation>
    </message>
    <message>
        <source>&amp;Undo</source>
        <translation>撤销(&amp;U)</translation>
    </message>
    <message>
        <source>&amp;Redo</source>
        <translation>重做(&amp;R)</translation>
    </message>
    <message>
        <source>Undo</source>
        <translation>撤销</translation>
    </message>
    <message>
        <source>Redo</source>
        <translation>重做</translation>
    </message>
    <message>
        <source>Turn</source>
        <translation>旋转</translation>
    </message>
    <message>
        <source>Drag to turn the view; drag a lesion to move it (Shift: resize it)</source>
        <translation>拖动以旋转视图；拖动病灶可移动它（按住 Shift：调整其大小）</translation>
    </message>
    <message>
        <source>Place lesion</source>
        <translation>放置病灶</translation>
    </message>
    <message>
        <source>Click on the organ to put a lesion under its surface there</source>
        <translation>单击器官，在该处表面下方放置一个病灶</translation>
    </message>
    <message>
        <source>Draw plane</source>
        <translation>绘制平面</translation>
    </message>
    <message>
        <source>Drag across the organ: the planned resection plane runs along the line, straight away from you (resection tasks)</source>
        <translation>在器官上拖出一条线：计划切除平面沿此线并垂直于屏幕向内延伸（切除任务）</translation>
    </message>
    <message>
        <source>Paint fixed</source>
        <translation>涂刷固定区</translation>
    </message>
    <message>
        <source>Drag over the surface to hold it fixed there (ligament attachments)</source>
        <translation>在表面上拖动，将所经之处固定（韧带附着处）</translation>
    </message>
    <message>
        <source>Try it</source>
        <translation>试运行</translation>
    </message>
    <message>
        <source>Run the scenario as it is now in the workstation</source>
        <translation>在工作站中按当前状态运行该场景</translation>
    </message>
    <message>
        <source>Add a lesion</source>
        <translation>添加病灶</translation>
    </message>
    <message>
        <source>Move the lesion</source>
        <translation>移动病灶</translation>
    </message>
    <message>
        <source>Resize the lesion</source>
        <translation>调整病灶大小</translation>
    </message>
    <message>
        <source>The organ cannot be built: %1</source>
        <translation>无法构建器官：%1</translation>
    </message>
    <message>
        <source> (the organ shown is the one before)</source>
        <translation> （显示的是之前的器官）</translation>
    </message>
    <message>
        <source>Organ: %1</source>
        <translation>器官：%1</translation>
    </message>
    <message>
        <source>untitled</source>
        <translation>未命名</translation>
    </message>
    <message>
        <source>Scenario editor — %1%2</source>
        <translation>场景编辑器 — %1%2</translation>
    </message>
    <message>
        <source>Click where the lobe is to be grasped.</source>
        <translation>请单击肝叶上要抓取的位置。</translation>
    </message>
    <message>
        <source>Place a lesion</source>
        <translation>放置病灶</translation>
    </message>
    <message>
        <source>Set the grasp point</source>
        <translation>设置抓取点</translation>
    </message>
    <message>
        <source>The grasp point is set.</source>
        <translation>已设置抓取点。</translation>
    </message>
    <message>
        <source>Paint a fixed region</source>
        <translation>涂刷固定区域</translation>
    </message>
    <message>
        <source>Draw the planned plane</source>
        <translation>绘制计划平面</translation>
    </message>
    <message>
        <source>Cannot open the scenario %1</source>
        <translation>无法打开场景 %1</translation>
    </message>
    <message>
        <source>Opened %1.</source>
        <translation>已打开 %1。</translation>
    </message>
    <message>
        <source>The scenario is not saved: fix these first</source>
        <translation>场景未保存：请先修正以下问题</translation>
    </message>
    <message>
        <source>Saved %1.</source>
        <translation>已保存 %1。</translation>
    </message>
    <message>
        <source>Unsaved changes</source>
        <translation>未保存的更改</translation>
    </message>
    <message>
        <source>The scenario has changes that are not saved. Save them?</source>
        <translation>场景有未保存的更改。是否保存？</translation>
    </message>
    <message>
        <source>The scenario cannot run: fix these first</source>
        <translation>场景无法运行：请先修正以下问题</translation>
    </message>
    <message>
        <source>Running the scenario in the workstation.</source>
        <translation>正在工作站中运行该场景。</translation>
    </message>
    <message>
        <source>%1 steps/s — measuring again…</source>
        <translation>%1 步/秒 — 正在重新测量…</translation>
    </message>
    <message>
        <source>Measuring the cost…</source>
        <translation>正在测量计算开销…</translation>
    </message>
    <message>
        <source>%1 steps/s, %2× real time (%3 elements)</source>
        <translation>%1 步/秒，%2 倍实时（%3 个单元）</translation>
    </message>
    <message>
        <source>; before the last change %1 steps/s</source>
        <translation>；上次更改前为 %1 步/秒</translation>
    </message>
    <message>
        <source>Not measured: %1</source>
        <translation>未测量：%1</translation>
    </message>
</context>
<context>
    <name>liversim::ScenarioPanel</name>
    <message>
        <source>probe</source>
        <translation>探针</translation>
    </message>
    <message>
        <source>forceps</source>
        <translation>抓钳</translation>
    </message>
    <message>
        <source>scalpel</source>
        <translation>手术刀</translation>
    </message>
    <message>
        <source>Palpate the liver and locate the lesion.</source>
        <translation>触诊肝脏并定位病灶。</translation>
    </message>
    <message>
        <source>Grasp the lobe and lift it by %1 mm.</source>
        <translation>抓住肝叶并将其提起 %1 mm。</translation>
    </message>
    <message>
        <source>Resect the lesion with a margin of at least %1 mm.</source>
        <translation>切除病灶，切缘至少 %1 mm。</translation>
    </message>
    <message>
        <source>%1
Time limit: %2:%3.</source>
        <translation>%1
时限：%2:%3。</translation>
    </message>
    <message>
        <source>Free practice</source>
        <translation>自由练习</translation>
    </message>
    <message>
        <source>The built-in liver, no task. File ▸ Open Scenario… loads one.</source>
        <translation>内置肝脏，无任务。可通过“文件 ▸ 打开场景…”加载场景。</translation>
    </message>
    <message>
        <source>near-incompressibility</source>
        <translation>近不可压缩性</translation>
    </message>
    <message>
        <source>viscoelasticity</source>
        <translation>粘弹性</translation>
    </message>
    <message>
        <source>viscoplasticity</source>
        <translation>粘塑性</translation>
    </message>
    <message>
        <source>fibres</source>
        <translation>纤维</translation>
    </message>
    <message>
        <source>elasticity only</source>
        <translation>仅弹性</translation>
    </message>
    <message numerus="yes">
        <source>%n lesion(s)</source>
        <translation>
            <numerusform>%n 个病灶</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>, %n hidden</source>
        <translation>
            <numerusform>，其中 %n 个隐藏</numerusform>
        </translation>
    </message>
    <message>
        <source>Tools: %1.
Simulated: %2.
%3.</source>
        <translation>器械：%1。
仿真效应：%2。
%3。</translation>
    </message>
    <message>
        <source>File: %1</source>
        <translation>文件：%1</translation>
    </message>
    <message>
        <source>Last session: peak force %1 N (free practice: no rubric).</source>
        <translation>上次训练：峰值力 %1 N（自由练习：无评分标准）。</translation>
    </message>
    <message>
        <source>Last session stored (no rubric).</source>
        <translation>上次训练已保存（无评分标准）。</translation>
    </message>
    <message>
        <source>was %1</source>
        <translation>实际为 %1</translation>
    </message>
    <message>
        <source>not done</source>
        <translation>未完成</translation>
    </message>
    <message>
        <source>Last session: score %1 %</source>
        <translation>上次训练：得分 %1%</translation>
    </message>
    <message>
        <source>, every criterion passed.</source>
        <translation>，所有标准均已通过。</translation>
    </message>
    <message>
        <source>. Not passed: %1.</source>
        <translation>。未通过：%1。</translation>
    </message>
    <message>
        <source>gravity</source>
        <translation>重力</translation>
    </message>
</context>
<context>
    <name>liversim::SessionReplayWindow</name>
    <message>
        <source>Replay of session %1</source>
        <translation>回放训练记录 %1</translation>
    </message>
    <message>
        <source>Recorded force on the tissue (N)</source>
        <translation>记录的组织受力 (N)</translation>
    </message>
    <message>
        <source>Replayed force on the tool (N)</source>
        <translation>回放的器械受力 (N)</translation>
    </message>
    <message>
        <source>Replayed time</source>
        <translation>回放时间</translation>
    </message>
    <message>
        <source>The replay ends at %1 s, where the integrator was changed (to %2): what followed was not logged for replay.</source>
        <translation>回放在 %1 s 处结束，此时时间积分器被更换（更换为 %2）：之后的过程未记录，无法回放。</translation>
    </message>
    <message>
        <source>Session %1 cannot be read: %2</source>
        <translation>无法读取训练记录 %1：%2</translation>
    </message>
    <message>
        <source>Session %1 was recorded without its simulation input (by a version before replays, or as a replay itself): it cannot be replayed in the viewport.</source>
        <translation>训练记录 %1 录制时未保存仿真输入（由支持回放之前的版本录制，或其本身就是一次回放）：无法在视口中回放。</translation>
    </message>
    <message>
        <source>Session %1 has no simulation input stored (it ended before its first cycle was saved).</source>
        <translation>训练记录 %1 没有保存仿真输入（在第一个周期保存之前就已结束）。</translation>
    </message>
    <message>
        <source>Building the session&apos;s scene…</source>
        <translation>正在构建训练记录的场景…</translation>
    </message>
    <message>
        <source>Session %1 cannot be replayed: %2</source>
        <translation>无法回放训练记录 %1：%2</translation>
    </message>
    <message>
        <source>Pause</source>
        <translation>暂停</translation>
    </message>
    <message>
        <source>Play</source>
        <translation>播放</translation>
    </message>
    <message>
        <source>%1 / %2 s</source>
        <translation>%1 / %2 s</translation>
    </message>
    <message>
        <source>Seeking to %1 s…</source>
        <translation>正在跳转到 %1 s…</translation>
    </message>
    <message>
        <source>Playing.</source>
        <translation>正在播放。</translation>
    </message>
    <message>
        <source>Paused.</source>
        <translation>已暂停。</translation>
    </message>
    <message>
        <source>See-through</source>
        <translation>透视</translation>
    </message>
    <message>
        <source>Show the liver semi-transparent, with the scenario&apos;s lesions inside</source>
        <translation>以半透明显示肝脏及其内部的场景病灶</translation>
    </message>
    <message>
        <source>The replay ends at %1 s, where the tissue was changed (to %2): what followed was not logged for replay.</source>
        <translation>回放在 %1 s 处结束，此时组织参数被更改（更改为 %2）：之后的过程未记录，无法回放。</translation>
    </message>
    <message>
        <source>Session %1 is not replayed: reading it was cancelled. Open the replay again to read it.</source>
        <translation>会话 %1 未回放：读取已取消。再次打开回放即可读取。</translation>
    </message>
    <message>
        <source>The replay ends at %1 s, where gravity was switched (to %2): what followed was not logged for replay.</source>
        <translation>回放在 %1 秒处结束，此时重力被切换（为 %2）：之后的操作未记录用于回放。</translation>
    </message>
    <message>
        <source>Left hand, recorded (N)</source>
        <translation>左手，记录 (N)</translation>
    </message>
    <message>
        <source>Left hand, replayed (N)</source>
        <translation>左手，回放 (N)</translation>
    </message>
    <message>
        <source>Right hand, recorded (N)</source>
        <translation>右手，记录 (N)</translation>
    </message>
    <message>
        <source>Right hand, replayed (N)</source>
        <translation>右手，回放 (N)</translation>
    </message>
</context>
<context>
    <name>liversim::SessionReviewWindow</name>
    <message>
        <source>Sessions of %1</source>
        <translation>%1 的训练记录</translation>
    </message>
    <message>
        <source>Sessions — %1</source>
        <translation>训练记录 — %1</translation>
    </message>
    <message>
        <source>Filter by trainee or scenario</source>
        <translation>按学员或场景筛选</translation>
    </message>
    <message>
        <source>Session</source>
        <translation>训练记录</translation>
    </message>
    <message>
        <source>Trainee</source>
        <translation>学员</translation>
    </message>
    <message>
        <source>Scenario</source>
        <translation>场景</translation>
    </message>
    <message>
        <source>Started</source>
        <translation>开始时间</translation>
    </message>
    <message>
        <source>Status</source>
        <translation>状态</translation>
    </message>
    <message>
        <source>Score</source>
        <translation>得分</translation>
    </message>
    <message>
        <source>Open a session to see it against its rubric.</source>
        <translation>打开一条训练记录，查看其对照评分标准的结果。</translation>
    </message>
    <message>
        <source>Metric</source>
        <translation>指标</translation>
    </message>
    <message>
        <source>Value</source>
        <translation>值</translation>
    </message>
    <message>
        <source>Criterion (weight)</source>
        <translation>标准（权重）</translation>
    </message>
    <message>
        <source>Passed</source>
        <translation>通过</translation>
    </message>
    <message>
        <source>Force on the device (N)</source>
        <translation>设备输出力 (N)</translation>
    </message>
    <message>
        <source>Events</source>
        <translation>事件</translation>
    </message>
    <message>
        <source>e.g. pass, fail, B+</source>
        <translation>例如：通过、不通过、B+</translation>
    </message>
    <message>
        <source>Save Grade</source>
        <translation>保存评分</translation>
    </message>
    <message>
        <source>Export CSV…</source>
        <translation>导出 CSV…</translation>
    </message>
    <message>
        <source>Export the session to</source>
        <translation>将训练记录导出到</translation>
    </message>
    <message>
        <source>Save Report as PDF…</source>
        <translation>将报告另存为 PDF…</translation>
    </message>
    <message>
        <source>Save the report</source>
        <translation>保存报告</translation>
    </message>
    <message>
        <source>PDF documents (*.pdf)</source>
        <translation>PDF 文档 (*.pdf)</translation>
    </message>
    <message>
        <source>Instructor:</source>
        <translation>教员：</translation>
    </message>
    <message>
        <source>Grade:</source>
        <translation>评分：</translation>
    </message>
    <message>
        <source>Comment:</source>
        <translation>评语：</translation>
    </message>
    <message>
        <source>Saved grades:</source>
        <translation>已保存的评分：</translation>
    </message>
    <message>
        <source>Replay in the Viewport…</source>
        <translation>在视口中回放…</translation>
    </message>
    <message>
        <source>Play the session back in a viewport from its recorded input, with its force plotted in step</source>
        <translation>根据记录的输入在视口中回放该训练记录，并同步绘制其力曲线</translation>
    </message>
    <message>
        <source>Export:</source>
        <translation>导出：</translation>
    </message>
    <message>
        <source>The sessions cannot be read: %1</source>
        <translation>无法读取训练记录：%1</translation>
    </message>
    <message>
        <source>not measured</source>
        <translation>未测量</translation>
    </message>
    <message>
        <source>yes</source>
        <translation>是</translation>
    </message>
    <message>
        <source>no</source>
        <translation>否</translation>
    </message>
    <message>
        <source>not graded</source>
        <translation>未评分</translation>
    </message>
    <message>
        <source>Force on the tissue (N)</source>
        <translation>组织受力 (N)</translation>
    </message>
    <message>
        <source>at (%1, %2, %3) mm</source>
        <translation>位于 (%1, %2, %3) mm</translation>
    </message>
    <message>
        <source>%1, %2: %3%4 — %5</source>
        <translation>%1，%2：%3%4 — %5</translation>
    </message>
    <message>
        <source> (score %1 %)</source>
        <translation> （得分 %1%）</translation>
    </message>
    <message>
        <source>none yet</source>
        <translation>暂无</translation>
    </message>
    <message>
        <source>Session %1 cannot be read: %2</source>
        <translation>无法读取训练记录 %1：%2</translation>
    </message>
    <message>
        <source>Session %1: its scenario has no rubric.</source>
        <translation>训练记录 %1：其场景没有评分标准。</translation>
    </message>
    <message>
        <source>Session %1: score %2 % (%3 of %4 criteria passed)</source>
        <translation>训练记录 %1：得分 %2%（%4 项标准中通过 %3 项）</translation>
    </message>
    <message>
        <source>Trainees cannot grade sessions.</source>
        <translation>学员不能为训练记录评分。</translation>
    </message>
    <message>
        <source>The grade was not saved: %1</source>
        <translation>评分未保存：%1</translation>
    </message>
    <message>
        <source>LiverSim session %1</source>
        <translation>LiverSim 训练记录 %1</translation>
    </message>
    <message>
        <source>Trainee: %1</source>
        <translation>学员：%1</translation>
    </message>
    <message>
        <source>Scenario: %1</source>
        <translation>场景：%1</translation>
    </message>
    <message>
        <source>Started: %1</source>
        <translation>开始时间：%1</translation>
    </message>
    <message>
        <source>Force on the device</source>
        <translation>设备输出力</translation>
    </message>
    <message>
        <source>Grades</source>
        <translation>评分</translation>
    </message>
    <message>
        <source>Nothing was exported: reading session %1 was cancelled.</source>
        <translation>未导出任何内容：会话 %1 的读取已取消。</translation>
    </message>
    <message>
        <source>(log in as an instructor to grade)</source>
        <translation>（以教师身份登录后方可评分）</translation>
    </message>
    <message>
        <source>Log in as an instructor to grade sessions (Settings ▸ Instructor Mode).</source>
        <translation>请以教师身份登录后为会话评分（设置 ▸ 教师模式）。</translation>
    </message>
    <message>
        <source>Enter the grade first (e.g. pass, fail, B+).</source>
        <translation>请先输入评分（例如 通过、不通过、B+）。</translation>
    </message>
    <message>
        <source>Left hand (N)</source>
        <translation>左手 (N)</translation>
    </message>
    <message>
        <source>Right hand (N)</source>
        <translation>右手 (N)</translation>
    </message>
    <message>
        <source> (left hand)</source>
        <translation>（左手）</translation>
    </message>
</context>
<context>
    <name>liversim::ToolPanel</name>
    <message>
        <source>&amp;Hand</source>
        <translation>手(&amp;H)</translation>
    </message>
    <message>
        <source>Drag the liver with the left mouse button: the tissue under it follows the pointer</source>
        <translation>按住鼠标左键拖动肝脏：指针下方的组织会跟随指针移动</translation>
    </message>
    <message>
        <source>&amp;Probe</source>
        <translation>探针(&amp;P)</translation>
    </message>
    <message>
        <source>&amp;Forceps</source>
        <translation>抓钳(&amp;F)</translation>
    </message>
    <message>
        <source>Press the left mouse button on the liver to close the jaws on it, drag to pull, release to let go</source>
        <translation>在肝脏上按下鼠标左键使钳口夹住组织，拖动以牵拉，松开按键即释放</translation>
    </message>
    <message>
        <source>&amp;Scalpel</source>
        <translation>手术刀(&amp;S)</translation>
    </message>
    <message>
        <source>Force on the tool: %1 N (holding tissue)</source>
        <translation>器械受力：%1 N（正在夹持组织）</translation>
    </message>
    <message>
        <source>Force on the tool: %1 N</source>
        <translation>器械受力：%1 N</translation>
    </message>
    <message>
        <source>Press the left mouse button on the liver to put the probe&apos;s ball on it, drag to move it; while the button is down, the wheel (or Shift+drag) pushes it in or draws it back</source>
        <translation>在肝脏上按下鼠标左键放上探针的球头，拖动以移动它；按住按键时，滚轮（或 Shift+拖动）将其推入或拉回</translation>
    </message>
    <message>
        <source>Press the left mouse button on the liver to put the blade in and drag: it cuts along its path. While the button is down, the wheel (or Shift+drag) pushes it deeper or draws it back; the panel shows how deep it is. Pressed on from outside, it breaks in once pressed hard enough to part the tissue</source>
        <translation>在肝脏上按下鼠标左键将刀刃插入并拖动：它沿路径切割。按住按键时，滚轮（或 Shift+拖动）将其推深或拉回；面板显示其深度。从外部按压时，压力足以分开组织时刀刃才切入</translation>
    </message>
    <message>
        <source>How much of the scalpel&apos;s edge is inside the tissue: its depth along the edge</source>
        <translation>手术刀刃在组织内的长度：沿刀刃的深度</translation>
    </message>
    <message>
        <source>Blade: not in the tissue</source>
        <translation>刀刃：不在组织内</translation>
    </message>
    <message>
        <source>Blade: %1 mm in the tissue, cutting</source>
        <translation>刀刃：%1 mm 在组织内，正在切割</translation>
    </message>
    <message>
        <source>Blade: %1 mm in the tissue</source>
        <translation>刀刃：%1 mm 在组织内</translation>
    </message>
</context>
<context>
    <name>liversim::TrainingCentreControl</name>
    <message>
        <source>There is no sessions database to upload from.</source>
        <translation>没有可供上传的训练数据库。</translation>
    </message>
    <message>
        <source>Training centre: not connected (Settings ▸ Training Centre Server…)</source>
        <translation>培训中心：未连接（设置 ▸ 培训中心服务器…）</translation>
    </message>
    <message>
        <source>Training centre: connecting to %1…</source>
        <translation>培训中心：正在连接 %1…</translation>
    </message>
    <message numerus="yes">
        <source>Training centre: %1 not reached, %n session(s) waiting</source>
        <translation>
            <numerusform>培训中心：无法连接 %1，%n 次训练等待上传</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>Training centre: up to date at %1, %n session(s) uploaded</source>
        <translation>
            <numerusform>培训中心：%1 时已同步，已上传 %n 次训练</numerusform>
        </translation>
    </message>
    <message>
        <source>No training centre server is set (Settings ▸ Training Centre Server…).</source>
        <translation>尚未设置培训中心服务器（设置 ▸ 培训中心服务器…）。</translation>
    </message>
    <message>
        <source>%1 is not an instructor on the server.</source>
        <translation>%1 不是服务器上的教员。</translation>
    </message>
</context>
<context>
    <name>liversim::TrainingCentreDialog</name>
    <message>
        <source>Training Centre Server</source>
        <translation>培训中心服务器</translation>
    </message>
    <message>
        <source>Finished sessions are uploaded to the training centre&apos;s server, and its published scenarios pulled, in the background. Recording never waits for the server. The password is not saved.</source>
        <translation>已结束的训练在后台上传到培训中心服务器，其发布的情景也在后台获取。记录从不等待服务器。密码不会被保存。</translation>
    </message>
    <message>
        <source>The password is in ~/.pgpass, or a client certificate is used (connect at every start)</source>
        <translation>密码在 ~/.pgpass 中，或使用客户端证书（每次启动时连接）</translation>
    </message>
    <message>
        <source>Server:</source>
        <translation>服务器：</translation>
    </message>
    <message>
        <source>Password:</source>
        <translation>密码：</translation>
    </message>
    <message>
        <source>Connect</source>
        <translation>连接</translation>
    </message>
</context>
<context>
    <name>main</name>
    <message>
        <source>LiverSim: real-time finite-element liver surgery training workstation</source>
        <translation>LiverSim：实时有限元肝脏手术训练工作站</translation>
    </message>
    <message>
        <source>Element count of the liver (100 to 2000000).</source>
        <translation>肝脏的单元数（100 至 2000000）。</translation>
    </message>
    <message>
        <source>Close the application this many seconds after the main window is shown (for unattended runs).</source>
        <translation>主窗口显示后经过指定秒数即关闭应用程序（用于无人值守运行）。</translation>
    </message>
    <message>
        <source>Run this scenario file (JSON, docs/scenario-format.md) instead of free practice on the built-in liver.</source>
        <translation>运行此场景文件（JSON，见 docs/scenario-format.md），而不是在内置肝脏上自由练习。</translation>
    </message>
    <message>
        <source>Record sessions to this SQLite file (default: sessions.sqlite in the user&apos;s data directory).</source>
        <translation>将训练记录保存到此 SQLite 文件（默认：用户数据目录中的 sessions.sqlite）。</translation>
    </message>
    <message>
        <source>LiverSim cannot start</source>
        <translation>LiverSim 无法启动</translation>
    </message>
    <message>
        <source>Interface language: en or zh_CN (default: the one chosen in Settings, else the system&apos;s).</source>
        <translation>界面语言：en 或 zh_CN（默认：“设置”中所选语言，否则跟随系统）。</translation>
    </message>
    <message>
        <source>A scenario file to run, as with --scenario.</source>
        <translation>要运行的场景文件，与 --scenario 相同。</translation>
    </message>
    <message>
        <source>The main window could not be opened: %1

Start LiverSim from a terminal to see its messages; liversim --help lists its options (a smaller liver: --tets N; another scenario: --scenario FILE).</source>
        <translation>无法打开主窗口：%1

请从终端启动 LiverSim 以查看其消息；liversim --help 列出其选项（更小的肝脏：--tets N；另一个场景：--scenario FILE）。</translation>
    </message>
    <message>
        <source>Drive the tool from the start with the scripted device playing this trajectory file (a line per point: time_s x_mm y_mm z_mm [buttons]); its session is recorded.</source>
        <translation>启动后即由播放此轨迹文件的脚本设备驱动器械（每行一个点：time_s x_mm y_mm z_mm [按钮]）；其会话会被录制。</translation>
    </message>
</context>
</TS>
